//! MCAP files (ROS 2's default storage), read with Foxglove's `mcap` crate in its
//! streaming (sans-io) mode: the file is fed in blocks, chunks (zstd, lz4 or
//! uncompressed) are decompressed one at a time and their CRCs checked.

use crate::collect::Collected;
use crate::error::{BagError, TRUNCATED_FIX};
use crate::limits::{chunk_limit, total_decompressed_limit};
use crate::wire::Encoding;
use mcap::records::op;
use mcap::sans_io::{LinearReadEvent, LinearReader, LinearReaderOptions};
use mcap::McapError;
use std::collections::HashMap;
use std::fs::File;
use std::io::Read;
use std::path::Path;

/// The first 8 bytes of an MCAP file.
pub(crate) const MAGIC: &[u8] = b"\x89MCAP0\r\n";

/// The bytes of a message record before its body: channel id (u16), sequence (u32),
/// log time (u64), publish time (u64).
const MESSAGE_HEADER: usize = 22;

/// What to tell the user about an error of the `mcap` crate.
fn advice(e: &McapError) -> &'static str {
    match e {
        McapError::UnsupportedCompression(_) => {
            "odocal reads zstd, lz4 and uncompressed chunks; recompress the file with \
             `mcap convert` or `ros2 bag convert`"
        }
        McapError::BadChunkCrc { .. } | McapError::BadChunkLength { .. } => {
            "a chunk is damaged; `mcap recover` can copy the readable chunks into a new file"
        }
        McapError::BadMagic => "the file is not an MCAP file",
        McapError::ChunkTooLarge(_) | McapError::RecordTooLarge { .. } => {
            "a record or decompressed chunk declares more than 64 times the file's size \
             (16 to 256 MiB): the file is damaged or hostile; `mcap recover` can copy the \
             readable chunks into a new file"
        }
        _ => TRUNCATED_FIX,
    }
}

/// A little-endian cursor over one record's bytes: every read bounds-checked, strings
/// borrowed (nothing allocated from a declared length).
struct Fields<'a> {
    b: &'a [u8],
    what: &'static str,
}

impl<'a> Fields<'a> {
    fn take(&mut self, n: usize, field: &str) -> Result<&'a [u8], String> {
        if n > self.b.len() {
            return Err(format!(
                "MCAP: {} record: field `{field}` needs {n} bytes, {} remain",
                self.what,
                self.b.len()
            ));
        }
        let (head, rest) = self.b.split_at(n);
        self.b = rest;
        Ok(head)
    }

    fn u16(&mut self, field: &str) -> Result<u16, String> {
        let s = self.take(2, field)?;
        Ok(u16::from_le_bytes([s[0], s[1]]))
    }

    fn string(&mut self, field: &str) -> Result<&'a str, String> {
        let s = self.take(4, field)?;
        let n = u32::from_le_bytes([s[0], s[1], s[2], s[3]]) as usize;
        let bytes = self.take(n, field)?;
        std::str::from_utf8(bytes)
            .map_err(|_| format!("MCAP: {} record: field `{field}` is not UTF-8", self.what))
    }
}

/// A schema record's id and name (the message type).
fn schema_head(data: &[u8]) -> Result<(u16, String), String> {
    let mut f = Fields {
        b: data,
        what: "schema",
    };
    let id = f.u16("id")?;
    Ok((id, f.string("name")?.to_string()))
}

/// The fields of a channel record that odocal uses.
struct ChannelHead<'a> {
    id: u16,
    schema_id: u16,
    topic: &'a str,
    message_encoding: &'a str,
}

/// A channel record's id, schema, topic and encoding (its metadata map is not read).
fn channel_head(data: &[u8]) -> Result<ChannelHead<'_>, String> {
    let mut f = Fields {
        b: data,
        what: "channel",
    };
    Ok(ChannelHead {
        id: f.u16("id")?,
        schema_id: f.u16("schema_id")?,
        topic: f.string("topic")?,
        message_encoding: f.string("message_encoding")?,
    })
}

/// Reads every record of the MCAP file at `path` into `out`; errors name the file
/// `name` (the compressed original when `path` is its decompressed copy).
pub(crate) fn read_mcap(path: &Path, name: &str, out: &mut Collected) -> Result<(), BagError> {
    let name = name.to_string();
    let mut file = File::open(path).map_err(|e| BagError::io(&name, e))?;
    let file_len = file.metadata().map_err(|e| BagError::io(&name, e))?.len();
    out.files.push(name.clone());
    let options = LinearReaderOptions::default()
        .with_validate_chunk_crcs(true)
        .with_record_length_limit(chunk_limit(file_len) as usize);
    let mut reader = LinearReader::new_with_options(options);
    let mut schemas: HashMap<u16, String> = HashMap::new();
    let mut channels: HashMap<u16, usize> = HashMap::new();
    let mut fed: u64 = 0;
    let mut records_bytes: u64 = 0;
    while let Some(event) = reader.next_event() {
        let event = event.map_err(|e| {
            BagError::format(
                &name,
                Some(fed),
                format!("MCAP: {e} (error found after reading this many bytes)"),
                advice(&e),
            )
        })?;
        match event {
            LinearReadEvent::ReadRequest(n) => {
                // Fed in blocks of at most 1 MiB: a record that declares more than the
                // file holds allocates only what is really read.
                let buf = reader.insert(n.clamp(1 << 16, 1 << 20));
                let got = file.read(buf).map_err(|e| BagError::io(&name, e))?;
                fed += got as u64;
                reader.notify_read(got);
            }
            LinearReadEvent::Record { opcode, data } => {
                records_bytes += data.len() as u64;
                if records_bytes > total_decompressed_limit(file_len) {
                    return Err(BagError::format(
                        &name,
                        Some(fed),
                        format!(
                            "the records up to here hold {records_bytes} bytes, more than the \
                             {} MiB a {file_len}-byte file may hold decompressed",
                            total_decompressed_limit(file_len) >> 20
                        ),
                        "the file is damaged or hostile; real files compress 2 to 10 times",
                    ));
                }
                match opcode {
                    op::MESSAGE => {
                        let Some(head) = data.get(..MESSAGE_HEADER) else {
                            return Err(BagError::format(
                                &name,
                                Some(fed),
                                "MCAP: a message record shorter than its header",
                                TRUNCATED_FIX,
                            ));
                        };
                        let channel = u16::from_le_bytes([head[0], head[1]]);
                        let mut t = [0u8; 8];
                        t.copy_from_slice(&head[6..14]);
                        let log_time = u64::from_le_bytes(t);
                        let Some(&i) = channels.get(&channel) else {
                            return Err(BagError::format(
                                &name,
                                Some(fed),
                                format!("MCAP: a message on channel {channel} before its channel"),
                                TRUNCATED_FIX,
                            ));
                        };
                        out.message(&name, i, log_time, &data[MESSAGE_HEADER..])?;
                    }
                    op::SCHEMA => {
                        let (id, type_name) = schema_head(data)
                            .map_err(|p| BagError::format(&name, Some(fed), p, TRUNCATED_FIX))?;
                        schemas.insert(id, type_name);
                    }
                    op::CHANNEL => {
                        let c = channel_head(data)
                            .map_err(|p| BagError::format(&name, Some(fed), p, TRUNCATED_FIX))?;
                        let type_name = match schemas.get(&c.schema_id) {
                            Some(n) => n.clone(),
                            None => String::from("(no schema)"),
                        };
                        let (encoding, type_name) = match c.message_encoding {
                            "cdr" => (Encoding::Cdr, type_name),
                            "ros1" => (Encoding::Ros1, type_name),
                            other => (Encoding::Cdr, format!("{type_name} ({other})")),
                        };
                        let i = out.topic(&name, c.topic, &type_name, encoding)?;
                        channels.insert(c.id, i);
                    }
                    _ => {}
                }
            }
        }
    }
    out.bytes_read += fed;
    Ok(())
}
