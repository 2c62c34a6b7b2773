//! ROS 2 SQLite bags (`.db3`), read with `rusqlite` and its bundled SQLite: the
//! `topics` table names each topic and type; message counts come from one aggregate
//! query, and only the messages of topics that may be used are fetched.
//!
//! A `.db3` is a program as much as data (views, generated columns, virtual tables
//! run code when queried), so the file is opened read-only without URI parsing, only
//! the two rosbag2 tables are queried and they must be plain tables, blobs and
//! SQLite's heap are capped at [`MAX_CHUNK_BYTES`] and the queries stop after
//! [`sqlite_time_limit`].

use crate::collect::Collected;
use crate::error::BagError;
use crate::limits::{sqlite_time_limit, MAX_CHUNK_BYTES};
use crate::wire::Encoding;
use rusqlite::limits::Limit;
use rusqlite::types::{Type, ValueRef};
use rusqlite::{Connection, OpenFlags, Row};
use std::path::Path;
use std::time::Instant;

/// The first 16 bytes of an SQLite database.
pub(crate) const MAGIC: &[u8] = b"SQLite format 3\0";

const NOT_A_BAG: &str = "the file is not a readable rosbag2 database (tables `topics` and \
                         `messages`); check it with `ros2 bag info`";

/// The name of an SQLite value type, for errors.
fn type_name(t: Type) -> &'static str {
    match t {
        Type::Null => "NULL",
        Type::Integer => "an integer",
        Type::Real => "a real number",
        Type::Text => "text",
        Type::Blob => "a blob",
    }
}

/// Column `col` (named `what`) of a row of `table`, as an integer.
fn integer(row: &Row, col: usize, what: &str, at: &dyn Fn() -> String) -> Result<i64, String> {
    match row.get_ref(col).map_err(|e| e.to_string())? {
        ValueRef::Integer(v) => Ok(v),
        v => Err(format!(
            "{}: column `{what}` is {}, expected an integer",
            at(),
            type_name(v.data_type())
        )),
    }
}

/// Column `col` (named `what`) of a row, as UTF-8 text.
fn text(row: &Row, col: usize, what: &str, at: &dyn Fn() -> String) -> Result<String, String> {
    match row.get_ref(col).map_err(|e| e.to_string())? {
        ValueRef::Text(t) => std::str::from_utf8(t)
            .map(str::to_string)
            .map_err(|_| format!("{}: column `{what}` is not UTF-8 text", at())),
        v => Err(format!(
            "{}: column `{what}` is {}, expected text",
            at(),
            type_name(v.data_type())
        )),
    }
}

/// Refuses anything but the two plain rosbag2 tables: views, virtual tables and
/// generated columns compute their rows when queried.
fn check_schema(db: &Connection) -> Result<(), String> {
    for table in ["topics", "messages"] {
        let found: Option<(String, String)> = db
            .query_row(
                "SELECT type, COALESCE(sql, '') FROM sqlite_master WHERE name = ?1",
                [table],
                |r| Ok((r.get(0)?, r.get(1)?)),
            )
            .map(Some)
            .or_else(|e| match e {
                rusqlite::Error::QueryReturnedNoRows => Ok(None),
                e => Err(e.to_string()),
            })?;
        match found {
            None => return Err(format!("no table `{table}`")),
            Some((kind, _)) if kind != "table" => {
                return Err(format!("`{table}` is a {kind}, not a table"))
            }
            Some((_, sql))
                if sql
                    .split_whitespace()
                    .take(2)
                    .any(|w| w.eq_ignore_ascii_case("VIRTUAL")) =>
            {
                return Err(format!("`{table}` is a virtual table"))
            }
            Some(_) => {}
        }
        let mut stmt = db
            .prepare(&format!("PRAGMA table_xinfo({table})"))
            .map_err(|e| e.to_string())?;
        let mut rows = stmt.query([]).map_err(|e| e.to_string())?;
        while let Some(r) = rows.next().map_err(|e| e.to_string())? {
            let hidden: i64 = r.get(6).map_err(|e| e.to_string())?;
            if hidden != 0 {
                let col: String = r.get(1).map_err(|e| e.to_string())?;
                return Err(format!(
                    "`{table}` has a generated or hidden column `{col}`"
                ));
            }
        }
    }
    Ok(())
}

/// Reads the rosbag2 SQLite file at `path` into `out`; errors name the file `name`
/// (the compressed original when `path` is its decompressed copy).
pub(crate) fn read_db3(path: &Path, name: &str, out: &mut Collected) -> Result<(), BagError> {
    let name = name.to_string();
    let file_len = std::fs::metadata(path)
        .map_err(|e| BagError::io(&name, e))?
        .len();
    let limit = sqlite_time_limit(file_len);
    let started = Instant::now();
    let bad = |problem: String| {
        let problem = if started.elapsed() >= limit {
            format!(
                "SQLite queries were stopped after {} s (a rosbag2 file of {file_len} bytes \
                 reads in far less): {problem}",
                limit.as_secs()
            )
        } else {
            format!("SQLite: {problem}")
        };
        BagError::format(&name, None, problem, NOT_A_BAG)
    };
    let sql = |e: rusqlite::Error| bad(e.to_string());
    // No SQLITE_OPEN_URI: the path is a file name, never `file:…?mode=…`.
    let db = Connection::open_with_flags(
        path,
        OpenFlags::SQLITE_OPEN_READ_ONLY | OpenFlags::SQLITE_OPEN_NO_MUTEX,
    )
    .map_err(sql)?;
    db.set_limit(Limit::SQLITE_LIMIT_LENGTH, MAX_CHUNK_BYTES as i32)
        .map_err(sql)?;
    // SQLite's own allocations (outside Rust's allocator) are capped as well.
    db.pragma_update(None, "hard_heap_limit", MAX_CHUNK_BYTES as i64)
        .map_err(sql)?;
    db.progress_handler(10_000, Some(move || started.elapsed() >= limit));
    check_schema(&db).map_err(bad)?;
    out.files.push(name.clone());
    let mut ids = Vec::new();
    {
        let mut stmt = db
            .prepare("SELECT id, name, type, serialization_format FROM topics ORDER BY id")
            .map_err(sql)?;
        let mut rows = stmt.query([]).map_err(sql)?;
        let mut k = 0u64;
        while let Some(r) = rows.next().map_err(sql)? {
            let at = || format!("row {k} of table `topics`");
            let id = integer(r, 0, "id", &at).map_err(bad)?;
            let topic = text(r, 1, "name", &at).map_err(bad)?;
            let type_name = text(r, 2, "type", &at).map_err(bad)?;
            let format = text(r, 3, "serialization_format", &at).map_err(bad)?;
            let type_name = if format == "cdr" {
                type_name
            } else {
                format!("{type_name} ({format})")
            };
            let i = out.topic(&name, &topic, &type_name, Encoding::Cdr)?;
            ids.push((id, i));
            k += 1;
        }
    }
    let index_of = |id: i64| ids.iter().find(|(k, _)| *k == id).map(|(_, i)| *i);
    // Counts and spans of every topic, decoded or not.
    let mut decoded = Vec::new();
    {
        let mut stmt = db
            .prepare(
                "SELECT topic_id, COUNT(*), MIN(timestamp), MAX(timestamp), SUM(LENGTH(data)) \
                 FROM messages GROUP BY topic_id",
            )
            .map_err(sql)?;
        let mut rows = stmt.query([]).map_err(sql)?;
        while let Some(r) = rows.next().map_err(sql)? {
            let at = || "table `messages`".to_string();
            let id = integer(r, 0, "topic_id", &at).map_err(bad)?;
            let Some(i) = index_of(id) else { continue };
            if out.decodes(i) {
                decoded.push((id, i));
                continue;
            }
            let at = || format!("the messages of topic {}", out.topics[i].name);
            let count = integer(r, 1, "COUNT(*)", &at).map_err(bad)?;
            let first = integer(r, 2, "timestamp", &at).map_err(bad)?;
            let last = integer(r, 3, "timestamp", &at).map_err(bad)?;
            let bytes = match r.get_ref(4).map_err(sql)? {
                ValueRef::Integer(v) => v,
                _ => 0,
            };
            out.count(i, count as u64, first as u64, last as u64, bytes as u64);
        }
    }
    // The messages of the topics that may be used, in recording order.
    for (id, i) in decoded {
        let mut stmt = db
            .prepare("SELECT id, timestamp, data FROM messages WHERE topic_id = ?1 ORDER BY id")
            .map_err(sql)?;
        let mut rows = stmt.query([id]).map_err(sql)?;
        while let Some(r) = rows.next().map_err(sql)? {
            let row_id = r.get_ref(0).ok().and_then(|v| v.as_i64().ok());
            let at = || {
                format!(
                    "message id {} of topic {} in table `messages`",
                    row_id.map_or("?".to_string(), |v| v.to_string()),
                    out.topics[i].name
                )
            };
            let t = integer(r, 1, "timestamp", &at).map_err(bad)?;
            let body = match r.get_ref(2).map_err(sql)? {
                ValueRef::Blob(b) => b,
                v => {
                    return Err(bad(format!(
                        "{}: column `data` is {}, expected a blob",
                        at(),
                        type_name(v.data_type())
                    )))
                }
            };
            out.message(&name, i, t.max(0) as u64, body)?;
        }
    }
    out.bytes_read += file_len;
    Ok(())
}
