//! ROS 2 SQLite bags (`.db3`), read with `rusqlite` and its bundled SQLite: the
//! `topics` table names each topic and type; message counts come from one aggregate
//! query, and only the messages of topics that may be used are fetched.

use crate::collect::Collected;
use crate::error::BagError;
use crate::wire::Encoding;
use rusqlite::{Connection, OpenFlags};
use std::path::Path;

/// The first 16 bytes of an SQLite database.
pub(crate) const MAGIC: &[u8] = b"SQLite format 3\0";

/// Reads the rosbag2 SQLite file at `path` into `out`.
pub(crate) fn read_db3(path: &Path, out: &mut Collected) -> Result<(), BagError> {
    let name = path.display().to_string();
    let bad = |e: rusqlite::Error| {
        BagError::format(
            &name,
            None,
            format!("SQLite: {e}"),
            "the file is not a readable rosbag2 database (tables `topics` and `messages`); \
             check it with `ros2 bag info`",
        )
    };
    let db = Connection::open_with_flags(
        path,
        OpenFlags::SQLITE_OPEN_READ_ONLY | OpenFlags::SQLITE_OPEN_NO_MUTEX,
    )
    .map_err(bad)?;
    out.files.push(name.clone());
    let mut ids = Vec::new();
    {
        let mut stmt = db
            .prepare("SELECT id, name, type, serialization_format FROM topics ORDER BY id")
            .map_err(bad)?;
        let rows = stmt
            .query_map([], |r| {
                Ok((
                    r.get::<_, i64>(0)?,
                    r.get::<_, String>(1)?,
                    r.get::<_, String>(2)?,
                    r.get::<_, String>(3)?,
                ))
            })
            .map_err(bad)?;
        for row in rows {
            let (id, topic, type_name, format) = row.map_err(bad)?;
            let type_name = if format == "cdr" {
                type_name
            } else {
                format!("{type_name} ({format})")
            };
            let i = out.topic(&name, &topic, &type_name, Encoding::Cdr)?;
            ids.push((id, i));
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
            .map_err(bad)?;
        let mut rows = stmt.query([]).map_err(bad)?;
        while let Some(r) = rows.next().map_err(bad)? {
            let id: i64 = r.get(0).map_err(bad)?;
            let Some(i) = index_of(id) else { continue };
            if out.decodes(i) {
                decoded.push((id, i));
                continue;
            }
            let count: i64 = r.get(1).map_err(bad)?;
            let first: i64 = r.get(2).map_err(bad)?;
            let last: i64 = r.get(3).map_err(bad)?;
            let bytes: i64 = r.get::<_, Option<i64>>(4).map_err(bad)?.unwrap_or(0);
            out.count(i, count as u64, first as u64, last as u64, bytes as u64);
        }
    }
    // The messages of the topics that may be used, in recording order.
    for (id, i) in decoded {
        let mut stmt = db
            .prepare("SELECT timestamp, data FROM messages WHERE topic_id = ?1 ORDER BY id")
            .map_err(bad)?;
        let mut rows = stmt.query([id]).map_err(bad)?;
        while let Some(r) = rows.next().map_err(bad)? {
            let t: i64 = r.get(0).map_err(bad)?;
            let data = r.get_ref(1).map_err(bad)?;
            let body = data.as_blob().map_err(|e| bad(e.into()))?;
            out.message(&name, i, t.max(0) as u64, body)?;
        }
    }
    out.bytes_read += std::fs::metadata(path).map(|m| m.len()).unwrap_or(0);
    Ok(())
}
