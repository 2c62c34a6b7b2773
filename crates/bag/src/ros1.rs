//! ROS 1 bags, format 2.0: records (`header_len`, header fields `name=value`,
//! `data_len`, data) read in file order; chunks (uncompressed, bz2 or lz4) are read
//! one at a time and walked for their connection and message records. The index
//! section is not needed. Memory: one chunk at a time.
//!
//! Written here rather than taken from the `rosbag` crate: that crate memory-maps the
//! whole file, reports damage as bare `InvalidHeader`/`InvalidRecord` without where or
//! which field (the issue asks for errors that say both), and links the C lz4 library.

use crate::collect::Collected;
use crate::error::{BagError, TRUNCATED_FIX};
use crate::limits::{chunk_limit, total_decompressed_limit};
use crate::wire::Encoding;
use std::collections::HashMap;
use std::fs::File;
use std::io::{BufReader, Read};
use std::path::Path;

/// The first line of every ROS 1 bag 2.0.
pub(crate) const MAGIC: &[u8] = b"#ROSBAG V2.0\n";

const OP_MESSAGE: u8 = 0x02;
const OP_BAG_HEADER: u8 = 0x03;
const OP_INDEX: u8 = 0x04;
const OP_CHUNK: u8 = 0x05;
const OP_CHUNK_INFO: u8 = 0x06;
const OP_CONNECTION: u8 = 0x07;

/// Largest record header accepted (headers are a few fields; the message definition
/// lives in the data).
const MAX_HEADER: u32 = 1 << 20;

/// The fields of a record header.
struct Fields<'a>(Vec<(&'a str, &'a [u8])>);

impl<'a> Fields<'a> {
    /// Parses `len name=value` fields.
    fn parse(mut b: &'a [u8]) -> Result<Self, String> {
        let mut out = Vec::new();
        while !b.is_empty() {
            let Some(len) = b.get(..4) else {
                return Err("a header field length is cut short".into());
            };
            let len = u32::from_le_bytes([len[0], len[1], len[2], len[3]]) as usize;
            let Some(field) = b.get(4..4 + len) else {
                return Err(format!("a header field claims {len} bytes past the header"));
            };
            let Some(eq) = field.iter().position(|&c| c == b'=') else {
                return Err("a header field has no `=`".into());
            };
            let name = std::str::from_utf8(&field[..eq])
                .map_err(|_| "a header field name is not UTF-8".to_string())?;
            out.push((name, &field[eq + 1..]));
            b = &b[4 + len..];
        }
        Ok(Fields(out))
    }

    fn get(&self, name: &str) -> Option<&'a [u8]> {
        self.0.iter().find(|(n, _)| *n == name).map(|(_, v)| *v)
    }

    fn op(&self) -> Result<u8, String> {
        match self.get("op") {
            Some([op]) => Ok(*op),
            _ => Err("a record without its one-byte `op` field".into()),
        }
    }

    fn u32(&self, name: &str) -> Result<u32, String> {
        match self.get(name) {
            Some(v) if v.len() == 4 => Ok(u32::from_le_bytes([v[0], v[1], v[2], v[3]])),
            _ => Err(format!("a record without its 4-byte `{name}` field")),
        }
    }

    fn time_ns(&self) -> Result<u64, String> {
        match self.get("time") {
            Some(v) if v.len() == 8 => {
                let sec = u32::from_le_bytes([v[0], v[1], v[2], v[3]]) as u64;
                let nsec = u32::from_le_bytes([v[4], v[5], v[6], v[7]]) as u64;
                Ok(sec * 1_000_000_000 + nsec)
            }
            _ => Err("a message record without its 8-byte `time` field".into()),
        }
    }

    fn text(&self, name: &str) -> Result<&'a str, String> {
        self.get(name)
            .and_then(|v| std::str::from_utf8(v).ok())
            .ok_or_else(|| format!("a record without a text `{name}` field"))
    }
}

/// Reading state: the file name and the connection → topic map.
struct Ros1Reader<'c> {
    name: String,
    connections: HashMap<u32, usize>,
    out: &'c mut Collected,
}

impl Ros1Reader<'_> {
    fn bad(&self, offset: u64, problem: impl Into<String>) -> BagError {
        BagError::format(&self.name, Some(offset), problem, TRUNCATED_FIX)
    }

    /// A connection record: header (conn, topic), data = connection header (type, …).
    fn connection(&mut self, offset: u64, h: &Fields, data: &[u8]) -> Result<(), BagError> {
        let conn = h.u32("conn").map_err(|p| self.bad(offset, p))?;
        let topic = h.text("topic").map_err(|p| self.bad(offset, p))?;
        let info = Fields::parse(data).map_err(|p| self.bad(offset, p))?;
        let type_name = info.text("type").map_err(|p| self.bad(offset, p))?;
        let i = self
            .out
            .topic(&self.name, topic, type_name, Encoding::Ros1)?;
        self.connections.insert(conn, i);
        Ok(())
    }

    /// A message record.
    fn message(&mut self, offset: u64, h: &Fields, data: &[u8]) -> Result<(), BagError> {
        let conn = h.u32("conn").map_err(|p| self.bad(offset, p))?;
        let t = h.time_ns().map_err(|p| self.bad(offset, p))?;
        let Some(&i) = self.connections.get(&conn) else {
            return Err(self.bad(
                offset,
                format!("a message on connection {conn} before its connection record"),
            ));
        };
        self.out.message(&self.name, i, t, data)
    }

    /// Walks the records of a (decompressed) chunk that starts at `offset` in the file.
    fn chunk_records(&mut self, offset: u64, mut b: &[u8]) -> Result<(), BagError> {
        while !b.is_empty() {
            let (h, data, rest) =
                split_record(b).map_err(|p| self.bad(offset, format!("inside the chunk: {p}")))?;
            let fields = Fields::parse(h).map_err(|p| self.bad(offset, p))?;
            match fields.op().map_err(|p| self.bad(offset, p))? {
                OP_CONNECTION => self.connection(offset, &fields, data)?,
                OP_MESSAGE => self.message(offset, &fields, data)?,
                op => {
                    return Err(
                        self.bad(offset, format!("a record of op 0x{op:02x} inside a chunk"))
                    )
                }
            }
            b = rest;
        }
        Ok(())
    }
}

/// A record's header, its data, and the bytes after it.
type RecordParts<'a> = (&'a [u8], &'a [u8], &'a [u8]);

/// Splits `header_len header data_len data rest`.
fn split_record(b: &[u8]) -> Result<RecordParts<'_>, String> {
    let len = |b: &[u8], at: usize| -> Option<usize> {
        let s = b.get(at..at + 4)?;
        Some(u32::from_le_bytes([s[0], s[1], s[2], s[3]]) as usize)
    };
    let hl = len(b, 0).ok_or("a record length is cut short")?;
    let h = b
        .get(4..4 + hl)
        .ok_or("a record header runs past the end")?;
    let dl = len(b, 4 + hl).ok_or("a record data length is cut short")?;
    let start = 8 + hl;
    let data = b
        .get(start..start + dl)
        .ok_or("a record's data runs past the end")?;
    Ok((h, data, &b[start + dl..]))
}

/// Decompresses a chunk's data into `out` (exactly `size` bytes expected).
fn decompress(
    compression: &str,
    data: &[u8],
    size: usize,
    out: &mut Vec<u8>,
) -> Result<(), String> {
    out.clear();
    // Grown as the data really decompresses, not as the header declares.
    out.reserve(size.min(data.len().saturating_mul(8)));
    let limit = size as u64 + 1;
    let got = match compression {
        "bz2" => bzip2::read::BzDecoder::new(data)
            .take(limit)
            .read_to_end(out),
        "lz4" => lz4_flex::frame::FrameDecoder::new(data)
            .take(limit)
            .read_to_end(out),
        other => {
            return Err(format!(
                "chunk compression `{other}` is not one of none, bz2, lz4"
            ))
        }
    };
    match got {
        Ok(n) if n == size => Ok(()),
        Ok(n) => Err(format!(
            "a {compression} chunk decompresses to {n} bytes, its header says {size}"
        )),
        Err(e) => Err(format!("a {compression} chunk does not decompress: {e}")),
    }
}

/// Reads every record of the ROS 1 bag at `path` into `out`.
pub(crate) fn read_ros1(path: &Path, out: &mut Collected) -> Result<(), BagError> {
    let name = path.display().to_string();
    let file = File::open(path).map_err(|e| BagError::io(&name, e))?;
    let file_len = file.metadata().map_err(|e| BagError::io(&name, e))?.len();
    let mut f = BufReader::with_capacity(1 << 16, file);
    let mut magic = [0u8; 13];
    let whole = f.read_exact(&mut magic).is_ok();
    if !whole || magic != MAGIC {
        return Err(BagError::format(
            &name,
            Some(0),
            "not a ROS 1 bag of format 2.0 (no `#ROSBAG V2.0` line)",
            "convert older bags with `rosbag fix`",
        ));
    }
    out.files.push(name.clone());
    let mut r = Ros1Reader {
        name,
        connections: HashMap::new(),
        out,
    };
    let mut pos = MAGIC.len() as u64;
    let mut header = Vec::new();
    let mut data = Vec::new();
    let mut plain = Vec::new();
    let mut index_pos = None;
    let mut decompressed = 0u64;
    while pos < file_len {
        let offset = pos;
        let header_len = read_u32(&mut f).map_err(|_| r.bad(offset, "a record cut short"))?;
        if header_len > MAX_HEADER || offset + 8 + header_len as u64 > file_len {
            return Err(r.bad(
                offset,
                format!("a record header of {header_len} bytes runs past the end of the file"),
            ));
        }
        header.resize(header_len as usize, 0);
        f.read_exact(&mut header)
            .map_err(|_| r.bad(offset, "a record header cut short"))?;
        let data_len = read_u32(&mut f).map_err(|_| r.bad(offset, "a record cut short"))?;
        let data_start = offset + 8 + header_len as u64;
        if data_start + data_len as u64 > file_len {
            return Err(r.bad(
                offset,
                format!(
                    "a record of {data_len} data bytes runs past the end of the file ({file_len} \
                     bytes)"
                ),
            ));
        }
        pos = data_start + data_len as u64;
        let fields = Fields::parse(&header).map_err(|p| r.bad(offset, p))?;
        match fields.op().map_err(|p| r.bad(offset, p))? {
            OP_CHUNK => {
                let compression = fields.text("compression").map_err(|p| r.bad(offset, p))?;
                let size = fields.u32("size").map_err(|p| r.bad(offset, p))?;
                if u64::from(size) > chunk_limit(file_len) {
                    return Err(BagError::format(
                        &r.name,
                        Some(offset),
                        format!(
                            "a chunk declares {size} bytes decompressed, more than the {} MiB \
                             a chunk of a {file_len}-byte bag may hold",
                            chunk_limit(file_len) >> 20
                        ),
                        "the bag is damaged or hostile; real chunks are a few MB (rosbag's \
                         default is 768 KiB)",
                    ));
                }
                data.resize(data_len as usize, 0);
                f.read_exact(&mut data)
                    .map_err(|_| r.bad(offset, "a chunk cut short"))?;
                decompressed += u64::from(size);
                if decompressed > total_decompressed_limit(file_len) {
                    return Err(BagError::format(
                        &r.name,
                        Some(offset),
                        format!(
                            "the chunks up to here decompress to {decompressed} bytes, more \
                             than the {} MiB a {file_len}-byte bag may hold",
                            total_decompressed_limit(file_len) >> 20
                        ),
                        "the bag is damaged or hostile; real bags compress 2 to 10 times",
                    ));
                }
                if compression == "none" {
                    if data.len() != size as usize {
                        return Err(r.bad(
                            offset,
                            format!(
                                "an uncompressed chunk of {} bytes, its header says {size}",
                                data.len()
                            ),
                        ));
                    }
                    r.chunk_records(offset, &data)?;
                } else {
                    if !matches!(compression, "bz2" | "lz4") {
                        return Err(BagError::format(
                            &r.name,
                            Some(offset),
                            format!(
                                "chunk compression `{compression}` is not one of none, bz2, lz4"
                            ),
                            "decompress the bag with `rosbag decompress` and read the result",
                        ));
                    }
                    decompress(compression, &data, size as usize, &mut plain)
                        .map_err(|p| r.bad(offset, p))?;
                    r.chunk_records(offset, &plain)?;
                }
            }
            op @ (OP_CONNECTION | OP_MESSAGE) => {
                data.resize(data_len as usize, 0);
                f.read_exact(&mut data)
                    .map_err(|_| r.bad(offset, "a record cut short"))?;
                if op == OP_CONNECTION {
                    r.connection(offset, &fields, &data)?;
                } else {
                    r.message(offset, &fields, &data)?;
                }
            }
            OP_BAG_HEADER => {
                let p = fields.get("index_pos").filter(|v| v.len() == 8);
                index_pos = p.map(|v| {
                    let mut b = [0u8; 8];
                    b.copy_from_slice(v);
                    u64::from_le_bytes(b)
                });
                f.seek_relative(data_len as i64)
                    .map_err(|e| BagError::io(&r.name, e))?;
            }
            OP_INDEX | OP_CHUNK_INFO => f
                .seek_relative(data_len as i64)
                .map_err(|e| BagError::io(&r.name, e))?,
            op => {
                return Err(r.bad(offset, format!("a record of unknown op 0x{op:02x}")));
            }
        }
    }
    r.out.bytes_read += file_len;
    if index_pos.is_none_or(|p| p == 0 || p > file_len) {
        let note = format!(
            "{}: the bag has no index (the recording was not closed); all its chunks were read",
            r.name
        );
        r.out.warnings.push(note);
    }
    Ok(())
}

fn read_u32(f: &mut impl Read) -> std::io::Result<u32> {
    let mut b = [0u8; 4];
    f.read_exact(&mut b)?;
    Ok(u32::from_le_bytes(b))
}
