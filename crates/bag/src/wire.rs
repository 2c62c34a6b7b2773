//! A bounds-checked reader of serialized message bodies: ROS 1 serialization (little
//! endian, packed, strings without terminator) and ROS 2 CDR (little or big endian as
//! its encapsulation header says, fields aligned to their size, strings with a NUL).
//! Every read checks the remaining length; a short or inconsistent body is an error
//! naming the field, never a panic.

use crate::limits::MAX_SEQUENCE_LEN;

/// How a message body is serialized.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Encoding {
    /// ROS 1 serialization (ROS 1 bags, MCAP channels with `ros1` encoding).
    Ros1,
    /// OMG CDR with a 4-byte encapsulation header (ROS 2 bags).
    Cdr,
}

/// Why a message body could not be decoded: the field and what was wrong.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct WireError {
    /// The field being read.
    pub field: &'static str,
    /// What was wrong.
    pub problem: String,
}

impl std::fmt::Display for WireError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "field `{}`: {}", self.field, self.problem)
    }
}

/// A cursor over one message body.
pub(crate) struct Wire<'a> {
    data: &'a [u8],
    pos: usize,
    /// Offset alignment is counted from (after the CDR encapsulation header).
    origin: usize,
    big_endian: bool,
    aligned: bool,
}

impl<'a> Wire<'a> {
    /// A cursor at the start of a body in `encoding`; for CDR, reads the encapsulation
    /// header (representation id 0x0000 big endian, 0x0001 little endian).
    pub(crate) fn new(data: &'a [u8], encoding: Encoding) -> Result<Self, WireError> {
        match encoding {
            Encoding::Ros1 => Ok(Wire {
                data,
                pos: 0,
                origin: 0,
                big_endian: false,
                aligned: false,
            }),
            Encoding::Cdr => {
                let Some(head) = data.get(..4) else {
                    return Err(WireError {
                        field: "CDR encapsulation header",
                        problem: format!("needs 4 bytes, the message has {}", data.len()),
                    });
                };
                let big_endian = match (head[0], head[1]) {
                    (0, 0) => true,
                    (0, 1) => false,
                    (a, b) => {
                        return Err(WireError {
                            field: "CDR encapsulation header",
                            problem: format!(
                                "representation 0x{a:02x}{b:02x} is not plain CDR \
                                 (0x0000 big endian or 0x0001 little endian)"
                            ),
                        })
                    }
                };
                Ok(Wire {
                    data,
                    pos: 4,
                    origin: 4,
                    big_endian,
                    aligned: true,
                })
            }
        }
    }

    fn short(&self, field: &'static str, need: usize) -> WireError {
        WireError {
            field,
            problem: format!(
                "needs {need} byte(s) at offset {} but the message has {}",
                self.pos,
                self.data.len()
            ),
        }
    }

    fn align(&mut self, n: usize) {
        if self.aligned {
            let rel = self.pos - self.origin;
            self.pos += (n - rel % n) % n;
        }
    }

    fn take(&mut self, field: &'static str, n: usize) -> Result<&'a [u8], WireError> {
        let end = self.pos.checked_add(n).filter(|&e| e <= self.data.len());
        match end {
            Some(end) => {
                let s = &self.data[self.pos..end];
                self.pos = end;
                Ok(s)
            }
            None => Err(self.short(field, n)),
        }
    }

    fn fixed<const N: usize>(&mut self, field: &'static str) -> Result<[u8; N], WireError> {
        self.align(N);
        let s = self.take(field, N)?;
        let mut b = [0u8; N];
        b.copy_from_slice(s);
        if self.big_endian {
            b.reverse();
        }
        Ok(b)
    }

    /// A `uint32`.
    pub(crate) fn u32(&mut self, field: &'static str) -> Result<u32, WireError> {
        Ok(u32::from_le_bytes(self.fixed(field)?))
    }

    /// An `int32`.
    pub(crate) fn i32(&mut self, field: &'static str) -> Result<i32, WireError> {
        Ok(i32::from_le_bytes(self.fixed(field)?))
    }

    /// A `float32`.
    pub(crate) fn f32(&mut self, field: &'static str) -> Result<f32, WireError> {
        Ok(f32::from_le_bytes(self.fixed(field)?))
    }

    /// A `float64`.
    pub(crate) fn f64(&mut self, field: &'static str) -> Result<f64, WireError> {
        Ok(f64::from_le_bytes(self.fixed(field)?))
    }

    /// A sequence length, checked against the bytes left (each element takes at least
    /// `min_element` bytes) and against [`MAX_SEQUENCE_LEN`], so a corrupt length cannot
    /// ask for a huge allocation.
    pub(crate) fn length(
        &mut self,
        field: &'static str,
        min_element: usize,
    ) -> Result<usize, WireError> {
        let at = self.pos;
        let n = self.u32(field)? as usize;
        let left = self.data.len() - self.pos;
        if n.saturating_mul(min_element.max(1)) > left {
            return Err(WireError {
                field,
                problem: format!(
                    "declares {n} element(s) at offset {at} but only {left} byte(s) follow"
                ),
            });
        }
        if min_element > 1 && n > MAX_SEQUENCE_LEN {
            return Err(WireError {
                field,
                problem: format!(
                    "declares {n} element(s) at offset {at}, more than the {MAX_SEQUENCE_LEN} \
                     a message may hold"
                ),
            });
        }
        Ok(n)
    }

    /// A string (UTF-8 checked, a CDR terminating NUL dropped).
    pub(crate) fn string(&mut self, field: &'static str) -> Result<&'a str, WireError> {
        let n = self.length(field, 1)?;
        let mut bytes = self.take(field, n)?;
        if self.aligned {
            match bytes.split_last() {
                Some((0, rest)) => bytes = rest,
                _ => {
                    return Err(WireError {
                        field,
                        problem: "CDR string without its terminating NUL".into(),
                    })
                }
            }
        }
        std::str::from_utf8(bytes).map_err(|_| WireError {
            field,
            problem: "string is not UTF-8".into(),
        })
    }

    /// A sequence of strings.
    pub(crate) fn strings(&mut self, field: &'static str) -> Result<Vec<&'a str>, WireError> {
        let n = self.length(field, 4)?;
        (0..n).map(|_| self.string(field)).collect()
    }

    /// A sequence of `float32`, appended to `out`; returns how many.
    pub(crate) fn f32_seq_into(
        &mut self,
        field: &'static str,
        out: &mut Vec<f32>,
    ) -> Result<usize, WireError> {
        let n = self.length(field, 4)?;
        if n > 0 {
            self.align(4);
        }
        let bytes = self.take(field, n * 4)?;
        let big = self.big_endian;
        out.extend(bytes.chunks_exact(4).map(|c| {
            let b = [c[0], c[1], c[2], c[3]];
            if big {
                f32::from_be_bytes(b)
            } else {
                f32::from_le_bytes(b)
            }
        }));
        Ok(n)
    }

    /// Skips a sequence of `float32`.
    pub(crate) fn skip_f32_seq(&mut self, field: &'static str) -> Result<(), WireError> {
        let n = self.length(field, 4)?;
        if n > 0 {
            self.align(4);
        }
        self.take(field, n * 4).map(|_| ())
    }

    /// A sequence of `float64`.
    pub(crate) fn f64_seq(&mut self, field: &'static str) -> Result<Vec<f64>, WireError> {
        let n = self.length(field, 8)?;
        (0..n).map(|_| self.f64(field)).collect()
    }

    /// Skips `n` consecutive `float64` (a fixed-size array such as a covariance).
    pub(crate) fn skip_f64s(&mut self, field: &'static str, n: usize) -> Result<(), WireError> {
        if n > 0 {
            self.align(8);
        }
        self.take(field, n * 8).map(|_| ())
    }

    /// A `std_msgs/Header`: returns its stamp in nanoseconds (ROS 1: seq, stamp,
    /// frame_id; ROS 2: stamp, frame_id).
    pub(crate) fn header_stamp_ns(&mut self) -> Result<i64, WireError> {
        Ok(self.header()?.0)
    }

    /// A `std_msgs/Header`: its stamp in nanoseconds and its frame_id.
    pub(crate) fn header(&mut self) -> Result<(i64, &'a str), WireError> {
        if !self.aligned {
            self.u32("header.seq")?;
        }
        let sec = if self.aligned {
            self.i32("header.stamp.sec")? as i64
        } else {
            self.u32("header.stamp.sec")? as i64
        };
        let nsec = self.u32("header.stamp.nanosec")? as i64;
        let frame = self.string("header.frame_id")?;
        Ok((sec * 1_000_000_000 + nsec, frame))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cdr_aligns_after_the_encapsulation_header() {
        // LE header, u32 7, then an f64 aligned to 8 (relative to offset 4).
        let mut b = vec![0, 1, 0, 0];
        b.extend(7u32.to_le_bytes());
        b.extend([0xaa; 4]);
        b.extend(2.5f64.to_le_bytes());
        let mut w = Wire::new(&b, Encoding::Cdr).unwrap();
        assert_eq!(w.u32("a").unwrap(), 7);
        assert_eq!(w.f64("b").unwrap(), 2.5);
        assert!(w.u32("c").is_err());
    }

    #[test]
    fn big_endian_cdr_reads() {
        let mut b = vec![0, 0, 0, 0];
        b.extend(3u32.to_be_bytes());
        b.extend(1.5f32.to_be_bytes());
        b.extend(2.0f32.to_be_bytes());
        b.extend(4.0f32.to_be_bytes());
        let mut w = Wire::new(&b, Encoding::Cdr).unwrap();
        let mut out = Vec::new();
        assert_eq!(w.f32_seq_into("r", &mut out).unwrap(), 3);
        assert_eq!(out, vec![1.5, 2.0, 4.0]);
    }

    #[test]
    fn a_huge_sequence_length_is_an_error_not_an_allocation() {
        let mut b = Vec::new();
        b.extend(u32::MAX.to_le_bytes());
        let mut w = Wire::new(&b, Encoding::Ros1).unwrap();
        let err = w.f64_seq("position").unwrap_err();
        assert_eq!(err.field, "position");
    }

    #[test]
    fn a_sequence_longer_than_the_cap_is_refused_even_when_its_bytes_are_there() {
        let n = MAX_SEQUENCE_LEN + 1;
        let mut b = Vec::with_capacity(4 + 4 * n);
        b.extend((n as u32).to_le_bytes());
        b.resize(4 + 4 * n, 0);
        let mut w = Wire::new(&b, Encoding::Ros1).unwrap();
        let err = w.strings("name").unwrap_err();
        assert!(err.problem.contains("more than"), "{err}");
    }
}
