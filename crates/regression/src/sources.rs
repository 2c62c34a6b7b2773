//! The published rows of a run: the Table I file's, then the T-RO reference's,
//! optionally narrowed to the rows asked for by name.

use crate::table::{read_table, PublishedRow, PublishedTable, TableError};
use crate::tro::read_tro_reference;
use std::path::{Path, PathBuf};

/// Why the rows of a run could not be gathered.
#[derive(Debug, thiserror::Error)]
pub enum SourceError {
    /// A table file or the reference could not be read.
    #[error(transparent)]
    Table(#[from] TableError),
    /// A row name is in both sources.
    #[error("row '{0}' is both in the Table I file and in the T-RO reference")]
    Duplicate(String),
    /// Neither source was found.
    #[error("no published rows: give --table FILE or --reference DIR")]
    NoRows,
    /// A row asked for by name does not exist.
    #[error("no row named '{wanted}'; the rows are {known}")]
    UnknownRow {
        /// The name asked for.
        wanted: String,
        /// The names of the rows, comma-separated.
        known: String,
    },
}

/// The published rows found, the Table I file's citation and UMBmark trials, and
/// notices about missing sources.
#[derive(Debug, Clone)]
pub struct Sources {
    /// The rows, the Table I file's first.
    pub rows: Vec<PublishedRow>,
    /// The Table I file, when one was found.
    pub table: Option<PublishedTable>,
    /// One sentence per missing source.
    pub notes: Vec<String>,
}

/// Reads the Table I file (`table`, else `fixtures/table-i.json` in the current
/// directory or the source tree, when it exists) and the T-RO reference in
/// `reference` (when it holds `lstraight_results.json`). A missing source is a note,
/// not an error.
pub fn load_sources(table: Option<&Path>, reference: &Path) -> Result<Sources, SourceError> {
    let mut rows = Vec::new();
    let mut notes = Vec::new();
    let table = match table {
        Some(p) => Some(p.to_path_buf()),
        None => [
            PathBuf::from("fixtures/table-i.json"),
            crate::table::workspace_table_path(),
        ]
        .into_iter()
        .find(|p| p.exists()),
    };
    let table = match table {
        Some(path) => {
            let t = read_table(&path)?;
            rows.extend(t.rows.iter().cloned());
            Some(t)
        }
        None => {
            notes.push(
                "No ICRA 2008 Table I file (fixtures/table-i.json here or in the source tree, \
                 or --table FILE): only the T-RO 2013 rows are compared."
                    .to_string(),
            );
            None
        }
    };
    if reference.join("lstraight_results.json").exists() {
        let tro = read_tro_reference(reference)?;
        for r in tro {
            if rows.iter().any(|o| o.name == r.name) {
                return Err(SourceError::Duplicate(r.name));
            }
            rows.push(r);
        }
    } else {
        notes.push(format!(
            "No T-RO 2013 reference data at {}: those rows are skipped.",
            reference.display()
        ));
    }
    Ok(Sources { rows, table, notes })
}

impl Sources {
    /// Keeps only the rows named in `names` (all rows when `names` is empty); an
    /// error when there are no rows or a name is unknown.
    pub fn select(&mut self, names: &[String]) -> Result<(), SourceError> {
        if self.rows.is_empty() {
            return Err(SourceError::NoRows);
        }
        if !names.is_empty() {
            let known: Vec<String> = self.rows.iter().map(|r| r.name.clone()).collect();
            for want in names {
                if !known.contains(want) {
                    return Err(SourceError::UnknownRow {
                        wanted: want.clone(),
                        known: known.join(", "),
                    });
                }
            }
            self.rows.retain(|r| names.contains(&r.name));
        }
        Ok(())
    }
}
