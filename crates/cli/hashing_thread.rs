//! A text log read, and its SHA-256 computed (when its outputs record it), on another
//! thread while the log is parsed: that thread reads the input in chunks through a [`Sha256Reader`] and hands
//! them over (moved, not copied) to the parser, so neither the system's copy of the
//! file's bytes nor hashing (≈ 0.5 ms per MB here) is on the parse's critical path. The
//! checksum is [`Sha256Reader`]'s for the same bytes.

use odocal_report::provenance::Sha256Reader;
use std::io::{self, BufRead, Read};
use std::sync::mpsc::{sync_channel, Receiver, SyncSender};
use std::thread::JoinHandle;

/// Bytes read from the input at a time.
const CHUNK_BYTES: u64 = 1 << 18;
/// Chunks read ahead of the parser at most (bounded memory: 4 MB).
const CHUNKS_AHEAD: usize = 16;

/// The SHA-256 (lower-case hex) and size in bytes of an input.
pub type Checksum = (String, u64);

/// A buffered reader of an input that another thread reads and hashes.
pub struct HashedInput {
    chunks: Receiver<io::Result<Vec<u8>>>,
    chunk: Vec<u8>,
    pos: usize,
    reader: Option<JoinHandle<io::Result<Option<Checksum>>>>,
}

impl HashedInput {
    /// Starts the thread that reads and hashes `inner`.
    pub fn new<R: Read + Send + 'static>(inner: R) -> io::Result<Self> {
        Self::start(inner, true)
    }

    /// Starts the thread that reads `inner` without hashing it ([`HashedInput::finish`]
    /// then gives no checksum): for runs whose outputs record no provenance, where
    /// hashing would only take a core from the parse.
    pub fn unhashed<R: Read + Send + 'static>(inner: R) -> io::Result<Self> {
        Self::start(inner, false)
    }

    fn start<R: Read + Send + 'static>(mut inner: R, hash: bool) -> io::Result<Self> {
        let (to_parser, chunks) = sync_channel(CHUNKS_AHEAD);
        let reader = std::thread::Builder::new()
            .name("read-ahead".into())
            .spawn(move || {
                if hash {
                    let mut hashing = Sha256Reader::new(inner);
                    pass_on(&mut hashing, to_parser)?;
                    hashing.finish().map(Some)
                } else {
                    pass_on(&mut inner, to_parser)?;
                    Ok(None)
                }
            })?;
        Ok(HashedInput {
            chunks,
            chunk: Vec::new(),
            pos: 0,
            reader: Some(reader),
        })
    }

    /// Reads the rest of the input, then returns the SHA-256 (lower-case hex) and size
    /// of all of it, as [`Sha256Reader::finish`] does (`None` when not hashed).
    pub fn finish(mut self) -> io::Result<Option<Checksum>> {
        loop {
            let n = self.fill_buf()?.len();
            if n == 0 {
                break;
            }
            self.consume(n);
        }
        match self.reader.take().map(JoinHandle::join) {
            Some(Ok(result)) => result,
            _ => Err(io::Error::other("the input's reading thread stopped")),
        }
    }
}

/// Reads `reader` to its end in chunks and sends them to the parser; a read error is
/// sent too, and returned.
fn pass_on<R: Read>(reader: &mut R, to_parser: SyncSender<io::Result<Vec<u8>>>) -> io::Result<()> {
    loop {
        let mut chunk = Vec::with_capacity(CHUNK_BYTES as usize);
        match reader.take(CHUNK_BYTES).read_to_end(&mut chunk) {
            Ok(0) => return Ok(()),
            Ok(_) => {
                if to_parser.send(Ok(chunk)).is_err() {
                    // The parser stopped (an error): the rest is not read.
                    return Err(io::Error::other("the input was not read to its end"));
                }
            }
            Err(e) => {
                let again = io::Error::new(e.kind(), e.to_string());
                let _ = to_parser.send(Err(e));
                return Err(again);
            }
        }
    }
}

impl BufRead for HashedInput {
    fn fill_buf(&mut self) -> io::Result<&[u8]> {
        if self.pos >= self.chunk.len() {
            self.pos = 0;
            self.chunk = match self.chunks.recv() {
                Ok(chunk) => chunk?,
                // The end of the input (or of the reading thread, reported by finish).
                Err(_) => Vec::new(),
            };
        }
        Ok(&self.chunk[self.pos..])
    }

    fn consume(&mut self, amount: usize) {
        self.pos = (self.pos + amount).min(self.chunk.len());
    }
}

impl Read for HashedInput {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        let available = self.fill_buf()?;
        let n = available.len().min(buf.len());
        buf[..n].copy_from_slice(&available[..n]);
        self.consume(n);
        Ok(n)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A reader that gives at most `step` bytes per read, as a pipe may.
    struct Trickle {
        bytes: Vec<u8>,
        at: usize,
        step: usize,
    }

    impl Read for Trickle {
        fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
            let n = self.step.min(buf.len()).min(self.bytes.len() - self.at);
            buf[..n].copy_from_slice(&self.bytes[self.at..self.at + n]);
            self.at += n;
            Ok(n)
        }
    }

    #[test]
    fn bytes_and_checksum_are_those_of_the_input() {
        let bytes: Vec<u8> = (0..3_000_000u32).map(|i| (i * 7 % 251) as u8).collect();
        let expected = Sha256Reader::new(&bytes[..]).finish().unwrap();
        for step in [1 << 20, 4099] {
            let mut input = HashedInput::new(Trickle {
                bytes: bytes.clone(),
                at: 0,
                step,
            })
            .unwrap();
            // Part read by `read`, part by lines, the rest left to `finish`.
            let mut head = vec![0u8; 1000];
            input.read_exact(&mut head).unwrap();
            assert_eq!(head, bytes[..1000]);
            let mut middle = Vec::new();
            input.read_until(200, &mut middle).unwrap();
            let upto = 1000 + middle.len();
            assert_eq!(middle, bytes[1000..upto]);
            let mut more = vec![0u8; 600_000];
            input.read_exact(&mut more).unwrap();
            assert_eq!(more, bytes[upto..upto + 600_000]);
            assert_eq!(input.finish().unwrap(), Some(expected.clone()));
            // Unhashed: the same bytes, no checksum.
            let mut input = HashedInput::unhashed(Trickle {
                bytes: bytes.clone(),
                at: 0,
                step,
            })
            .unwrap();
            let mut all = Vec::new();
            input.read_to_end(&mut all).unwrap();
            assert_eq!(all, bytes);
            assert_eq!(input.finish().unwrap(), None);
        }
        let empty = HashedInput::new(io::empty()).unwrap().finish().unwrap();
        assert_eq!(empty, Some(Sha256Reader::new(&b""[..]).finish().unwrap()));
    }

    #[test]
    fn a_read_error_is_returned() {
        struct Broken;
        impl Read for Broken {
            fn read(&mut self, _: &mut [u8]) -> io::Result<usize> {
                Err(io::Error::other("disk on fire"))
            }
        }
        for mut input in [
            HashedInput::new(Broken).unwrap(),
            HashedInput::unhashed(Broken).unwrap(),
        ] {
            let e = input.fill_buf().unwrap_err();
            assert!(e.to_string().contains("disk on fire"));
            assert!(input.finish().is_err());
        }
    }
}
