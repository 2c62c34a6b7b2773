//! The SHA-256 of a text log computed on another thread while the log is parsed. The
//! input is read once, in chunks that the parser and the hashing thread share (not
//! copied), so hashing (≈ 0.5 ms per MB here) is off the parse's critical path; the
//! checksum is the one [`Sha256Reader`] gives for the same bytes.

use odocal_report::provenance::Sha256Reader;
use std::io::{self, BufRead, Read};
use std::sync::mpsc::{sync_channel, Receiver, SyncSender};
use std::sync::Arc;
use std::thread::JoinHandle;

/// Bytes read from the input at a time.
const CHUNK_BYTES: u64 = 1 << 18;
/// Chunks read ahead of the hashing thread at most (bounded memory: 4 MB).
const CHUNKS_AHEAD: usize = 16;

/// A buffered reader of `inner` whose bytes are hashed on another thread.
pub struct HashedInput<R> {
    inner: R,
    chunk: Arc<Vec<u8>>,
    pos: usize,
    to_hasher: Option<SyncSender<Arc<Vec<u8>>>>,
    hasher: Option<JoinHandle<io::Result<(String, u64)>>>,
}

impl<R: Read> HashedInput<R> {
    /// Wraps `inner` and starts the hashing thread.
    pub fn new(inner: R) -> io::Result<Self> {
        let (to_hasher, chunks) = sync_channel(CHUNKS_AHEAD);
        let hasher = std::thread::Builder::new()
            .name("sha256".into())
            .spawn(move || Sha256Reader::new(Chunks::new(chunks)).finish())?;
        Ok(HashedInput {
            inner,
            chunk: Arc::new(Vec::new()),
            pos: 0,
            to_hasher: Some(to_hasher),
            hasher: Some(hasher),
        })
    }

    /// Reads the rest of the input, then returns the SHA-256 (lower-case hex) and size
    /// of all of it, as [`Sha256Reader::finish`] does.
    pub fn finish(mut self) -> io::Result<(String, u64)> {
        loop {
            let n = self.fill_buf()?.len();
            if n == 0 {
                break;
            }
            self.consume(n);
        }
        drop(self.to_hasher.take());
        match self.hasher.take().map(JoinHandle::join) {
            Some(Ok(result)) => result,
            _ => Err(io::Error::other("the checksum thread stopped")),
        }
    }
}

impl<R: Read> BufRead for HashedInput<R> {
    fn fill_buf(&mut self) -> io::Result<&[u8]> {
        if self.pos >= self.chunk.len() {
            let mut next = Vec::with_capacity(CHUNK_BYTES as usize);
            (&mut self.inner).take(CHUNK_BYTES).read_to_end(&mut next)?;
            self.chunk = Arc::new(next);
            self.pos = 0;
            if !self.chunk.is_empty() {
                if let Some(tx) = &self.to_hasher {
                    // A hashing thread that stopped is reported by `finish`.
                    let _ = tx.send(Arc::clone(&self.chunk));
                }
            }
        }
        Ok(&self.chunk[self.pos..])
    }

    fn consume(&mut self, amount: usize) {
        self.pos = (self.pos + amount).min(self.chunk.len());
    }
}

impl<R: Read> Read for HashedInput<R> {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        let available = self.fill_buf()?;
        let n = available.len().min(buf.len());
        buf[..n].copy_from_slice(&available[..n]);
        self.consume(n);
        Ok(n)
    }
}

/// The chunks received by the hashing thread, read as one stream (it ends when the
/// reader is finished or dropped).
struct Chunks {
    from_reader: Receiver<Arc<Vec<u8>>>,
    chunk: Arc<Vec<u8>>,
    pos: usize,
}

impl Chunks {
    fn new(from_reader: Receiver<Arc<Vec<u8>>>) -> Self {
        Chunks {
            from_reader,
            chunk: Arc::new(Vec::new()),
            pos: 0,
        }
    }
}

impl Read for Chunks {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        while self.pos >= self.chunk.len() {
            match self.from_reader.recv() {
                Ok(chunk) => {
                    self.chunk = chunk;
                    self.pos = 0;
                }
                Err(_) => return Ok(0),
            }
        }
        let n = (self.chunk.len() - self.pos).min(buf.len());
        buf[..n].copy_from_slice(&self.chunk[self.pos..self.pos + n]);
        self.pos += n;
        Ok(n)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A reader that gives at most `step` bytes per read, as a pipe may.
    struct Trickle<'a> {
        bytes: &'a [u8],
        step: usize,
    }

    impl Read for Trickle<'_> {
        fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
            let n = self.step.min(buf.len()).min(self.bytes.len());
            buf[..n].copy_from_slice(&self.bytes[..n]);
            self.bytes = &self.bytes[n..];
            Ok(n)
        }
    }

    #[test]
    fn bytes_and_checksum_are_those_of_the_input() {
        let bytes: Vec<u8> = (0..3_000_000u32).map(|i| (i * 7 % 251) as u8).collect();
        let expected = Sha256Reader::new(&bytes[..]).finish().unwrap();
        for step in [1 << 20, 4099] {
            let mut input = HashedInput::new(Trickle {
                bytes: &bytes,
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
            assert_eq!(input.finish().unwrap(), expected);
        }
        let empty = HashedInput::new(&b""[..]).unwrap().finish().unwrap();
        assert_eq!(empty, Sha256Reader::new(&b""[..]).finish().unwrap());
    }

    #[test]
    fn a_read_error_is_returned() {
        struct Broken;
        impl Read for Broken {
            fn read(&mut self, _: &mut [u8]) -> io::Result<usize> {
                Err(io::Error::other("disk on fire"))
            }
        }
        let mut input = HashedInput::new(Broken).unwrap();
        let e = input.fill_buf().unwrap_err();
        assert!(e.to_string().contains("disk on fire"));
        assert!(input.finish().is_err());
    }
}
