//! A minimal CDR (little-endian, ROS 2 / DDS XCDR1) encoder and decoder for the recording's own
//! channels. Messages start with the 4-byte encapsulation header `00 01 00 00`; each primitive
//! is aligned to its size, measured from the end of the header; strings are a u32 length
//! (including the terminating NUL), the bytes and a NUL; sequences are a u32 count and the
//! elements; fixed arrays have no count. f64 values are stored as their exact bits.

/// Errors decoding a CDR message.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum CdrError {
    /// The message ended early.
    #[error("message ends at byte {at} while reading {what}")]
    Eof {
        /// Offset reached.
        at: usize,
        /// What was being read.
        what: &'static str,
    },
    /// The encapsulation header is not CDR little-endian.
    #[error("encapsulation header {0:02x?} is not CDR little-endian (00 01 00 00)")]
    Header(Vec<u8>),
    /// A string is not NUL-terminated UTF-8.
    #[error("string at byte {0} is not NUL-terminated UTF-8")]
    BadString(usize),
    /// Bytes left after the last field.
    #[error("{0} bytes left after the last field")]
    Trailing(usize),
    /// Fields that contradict each other (e.g. sequences of different lengths).
    #[error("{0}")]
    Invalid(String),
    /// A recording of another format version.
    #[error(
        "recorded with format {0}; this build reads {fmt} (re-record the session, or replay it with the build that wrote it)",
        fmt = super::FORMAT_VERSION
    )]
    Format(String),
}

const HEADER: [u8; 4] = [0x00, 0x01, 0x00, 0x00];

/// Encodes one CDR message.
#[derive(Debug)]
pub struct CdrWriter {
    buf: Vec<u8>,
}

impl Default for CdrWriter {
    fn default() -> Self {
        Self::new()
    }
}

impl CdrWriter {
    /// A writer holding just the encapsulation header.
    pub fn new() -> Self {
        let mut buf = Vec::with_capacity(128);
        buf.extend_from_slice(&HEADER);
        CdrWriter { buf }
    }

    fn align(&mut self, n: usize) {
        while (self.buf.len() - 4) % n != 0 {
            self.buf.push(0);
        }
    }

    /// Writes a `uint8`.
    pub fn u8(&mut self, v: u8) -> &mut Self {
        self.buf.push(v);
        self
    }

    /// Writes a `bool`.
    pub fn bool(&mut self, v: bool) -> &mut Self {
        self.u8(u8::from(v))
    }

    /// Writes a `uint32`.
    pub fn u32(&mut self, v: u32) -> &mut Self {
        self.align(4);
        self.buf.extend_from_slice(&v.to_le_bytes());
        self
    }

    /// Writes a `uint64`.
    pub fn u64(&mut self, v: u64) -> &mut Self {
        self.align(8);
        self.buf.extend_from_slice(&v.to_le_bytes());
        self
    }

    /// Writes an `int64`.
    pub fn i64(&mut self, v: i64) -> &mut Self {
        self.align(8);
        self.buf.extend_from_slice(&v.to_le_bytes());
        self
    }

    /// Writes a `float64` (its exact bits).
    pub fn f64(&mut self, v: f64) -> &mut Self {
        self.align(8);
        self.buf.extend_from_slice(&v.to_bits().to_le_bytes());
        self
    }

    /// Writes a fixed-size `float64[N]`.
    pub fn f64s(&mut self, v: &[f64]) -> &mut Self {
        for x in v {
            self.f64(*x);
        }
        self
    }

    /// Writes a `float64[]` (unbounded sequence: a u32 count, then the elements).
    pub fn f64_seq(&mut self, v: &[f64]) -> &mut Self {
        self.u32(v.len() as u32);
        self.f64s(v)
    }

    /// Writes a `string`.
    pub fn string(&mut self, s: &str) -> &mut Self {
        self.u32(s.len() as u32 + 1);
        self.buf.extend_from_slice(s.as_bytes());
        self.buf.push(0);
        self
    }

    /// Writes a `string[]` (unbounded sequence).
    pub fn strings<'a>(&mut self, v: impl ExactSizeIterator<Item = &'a str>) -> &mut Self {
        self.u32(v.len() as u32);
        for s in v {
            self.string(s);
        }
        self
    }

    /// The encoded message.
    pub fn finish(&mut self) -> Vec<u8> {
        std::mem::take(&mut self.buf)
    }
}

/// Decodes one CDR message.
#[derive(Debug)]
pub struct CdrReader<'a> {
    buf: &'a [u8],
    pos: usize,
}

impl<'a> CdrReader<'a> {
    /// A reader over `buf`, checking the encapsulation header.
    pub fn new(buf: &'a [u8]) -> Result<Self, CdrError> {
        if buf.len() < 4 || buf[..4] != HEADER {
            return Err(CdrError::Header(buf.iter().take(4).copied().collect()));
        }
        Ok(CdrReader { buf, pos: 4 })
    }

    fn align(&mut self, n: usize) {
        while (self.pos - 4) % n != 0 {
            self.pos += 1;
        }
    }

    fn take(&mut self, n: usize, what: &'static str) -> Result<&'a [u8], CdrError> {
        if self.pos + n > self.buf.len() {
            return Err(CdrError::Eof { at: self.pos, what });
        }
        let s = &self.buf[self.pos..self.pos + n];
        self.pos += n;
        Ok(s)
    }

    /// Reads a `uint8`.
    pub fn u8(&mut self) -> Result<u8, CdrError> {
        Ok(self.take(1, "uint8")?[0])
    }

    /// Reads a `bool`.
    pub fn bool(&mut self) -> Result<bool, CdrError> {
        Ok(self.u8()? != 0)
    }

    /// Reads a `uint32`.
    pub fn u32(&mut self) -> Result<u32, CdrError> {
        self.align(4);
        let b = self.take(4, "uint32")?;
        Ok(u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
    }

    fn b8(&mut self, what: &'static str) -> Result<[u8; 8], CdrError> {
        self.align(8);
        let b = self.take(8, what)?;
        let mut a = [0u8; 8];
        a.copy_from_slice(b);
        Ok(a)
    }

    /// Reads a `uint64`.
    pub fn u64(&mut self) -> Result<u64, CdrError> {
        Ok(u64::from_le_bytes(self.b8("uint64")?))
    }

    /// Reads an `int64`.
    pub fn i64(&mut self) -> Result<i64, CdrError> {
        Ok(i64::from_le_bytes(self.b8("int64")?))
    }

    /// Reads a `float64`.
    pub fn f64(&mut self) -> Result<f64, CdrError> {
        Ok(f64::from_bits(u64::from_le_bytes(self.b8("float64")?)))
    }

    /// Reads a `float64[3]`.
    pub fn vec3(&mut self) -> Result<[f64; 3], CdrError> {
        Ok([self.f64()?, self.f64()?, self.f64()?])
    }

    /// Reads a `string`.
    pub fn string(&mut self) -> Result<String, CdrError> {
        let n = self.u32()? as usize;
        let at = self.pos;
        if n == 0 {
            return Err(CdrError::BadString(at));
        }
        let b = self.take(n, "string")?;
        if b[n - 1] != 0 {
            return Err(CdrError::BadString(at));
        }
        String::from_utf8(b[..n - 1].to_vec()).map_err(|_| CdrError::BadString(at))
    }

    /// Reads a sequence's length, refusing one the rest of the message cannot hold when each
    /// element takes at least `min_bytes` (`what` names the sequence in the error).
    fn seq_len(&mut self, min_bytes: usize, what: &'static str) -> Result<usize, CdrError> {
        let n = self.u32()? as usize;
        if n > (self.buf.len() - self.pos) / min_bytes {
            return Err(CdrError::Eof { at: self.pos, what });
        }
        Ok(n)
    }

    /// Reads a `float64[]` (unbounded sequence).
    pub fn f64_seq(&mut self) -> Result<Vec<f64>, CdrError> {
        // each element takes 8 bytes
        let n = self.seq_len(8, "float64[]")?;
        (0..n).map(|_| self.f64()).collect()
    }

    /// Reads a `string[]`.
    pub fn strings(&mut self) -> Result<Vec<String>, CdrError> {
        // each string takes at least 5 bytes: its length and its terminating NUL
        let n = self.seq_len(5, "string[]")?;
        (0..n).map(|_| self.string()).collect()
    }

    /// Bytes not read yet.
    pub fn remaining(&self) -> usize {
        self.buf.len() - self.pos
    }

    /// Checks that the whole message was read.
    pub fn end(&self) -> Result<(), CdrError> {
        match self.buf.len() - self.pos {
            0 => Ok(()),
            n => Err(CdrError::Trailing(n)),
        }
    }
}

/// A value that is one field of a recording message: its ROS 2 `.msg` type and its CDR
/// encoding (the declarations in [`super::messages`] build every encoder and decoder from it).
pub trait CdrField: Sized {
    /// The field's type in the `.msg` schema text (`uint64`, `float64[3]`, `string[]`, …).
    const MSG_TYPE: &'static str;
    /// Appends the value to `w`.
    fn put(&self, w: &mut CdrWriter);
    /// Reads the value from `r`.
    fn get(r: &mut CdrReader<'_>) -> Result<Self, CdrError>;
}

macro_rules! cdr_scalar {
    ($($t:ty, $msg:literal, $put:ident;)*) => {$(
        impl CdrField for $t {
            const MSG_TYPE: &'static str = $msg;
            fn put(&self, w: &mut CdrWriter) {
                w.$put(*self);
            }
            fn get(r: &mut CdrReader<'_>) -> Result<Self, CdrError> {
                r.$put()
            }
        }
    )*};
}

cdr_scalar! {
    u8, "uint8", u8;
    bool, "bool", bool;
    u32, "uint32", u32;
    u64, "uint64", u64;
    i64, "int64", i64;
    f64, "float64", f64;
}

impl CdrField for [f64; 3] {
    const MSG_TYPE: &'static str = "float64[3]";
    fn put(&self, w: &mut CdrWriter) {
        w.f64s(self);
    }
    fn get(r: &mut CdrReader<'_>) -> Result<Self, CdrError> {
        r.vec3()
    }
}

impl CdrField for [f64; 9] {
    const MSG_TYPE: &'static str = "float64[9]";
    fn put(&self, w: &mut CdrWriter) {
        w.f64s(self);
    }
    fn get(r: &mut CdrReader<'_>) -> Result<Self, CdrError> {
        let mut k = [0.0; 9];
        for v in &mut k {
            *v = r.f64()?;
        }
        Ok(k)
    }
}

impl CdrField for String {
    const MSG_TYPE: &'static str = "string";
    fn put(&self, w: &mut CdrWriter) {
        w.string(self);
    }
    fn get(r: &mut CdrReader<'_>) -> Result<Self, CdrError> {
        r.string()
    }
}

impl CdrField for Vec<String> {
    const MSG_TYPE: &'static str = "string[]";
    fn put(&self, w: &mut CdrWriter) {
        w.strings(self.iter().map(String::as_str));
    }
    fn get(r: &mut CdrReader<'_>) -> Result<Self, CdrError> {
        r.strings()
    }
}

impl CdrField for Vec<f64> {
    const MSG_TYPE: &'static str = "float64[]";
    fn put(&self, w: &mut CdrWriter) {
        w.f64_seq(self);
    }
    fn get(r: &mut CdrReader<'_>) -> Result<Self, CdrError> {
        r.f64_seq()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn layout_follows_cdr_alignment() {
        let mut w = CdrWriter::new();
        w.u8(7).u64(1).string("ab").f64(0.5);
        let b = w.finish();
        // header 4 | u8 at 0 | pad to 8 | u64 | u32 len=3 | 'a' 'b' 0 | pad to 8 | f64
        assert_eq!(b.len(), 4 + 8 + 8 + 4 + 3 + 1 + 8);
        assert_eq!(&b[12..20], &1u64.to_le_bytes());
        assert_eq!(&b[20..24], &3u32.to_le_bytes());
        assert_eq!(&b[24..27], b"ab\0");
    }

    proptest! {
        #[test]
        fn roundtrip_is_bit_exact(bits in any::<u64>(), t in any::<u64>(), s in "[a-z.]{0,12}", n in any::<u32>(), f in any::<bool>()) {
            let x = f64::from_bits(bits);
            let mut w = CdrWriter::new();
            w.bool(f).u64(t).f64(x).u32(n).string(&s).strings([s.as_str(), "x"].into_iter());
            let b = w.finish();
            let mut r = CdrReader::new(&b).unwrap();
            prop_assert_eq!(r.bool().unwrap(), f);
            prop_assert_eq!(r.u64().unwrap(), t);
            prop_assert_eq!(r.f64().unwrap().to_bits(), bits);
            prop_assert_eq!(r.u32().unwrap(), n);
            prop_assert_eq!(r.string().unwrap(), s.clone());
            prop_assert_eq!(r.strings().unwrap(), vec![s.clone(), "x".to_string()]);
            prop_assert!(r.end().is_ok());
        }

        #[test]
        fn truncated_messages_error_not_panic(cut in 0usize..40) {
            let mut w = CdrWriter::new();
            w.u64(3).string("hello").f64(1.0);
            let b = w.finish();
            let b = &b[..cut.min(b.len())];
            let res = CdrReader::new(b).and_then(|mut r| { r.u64()?; r.string()?; r.f64()?; r.end() });
            prop_assert_eq!(b.len(), cut.min(36));
            prop_assert_eq!(res.is_ok(), cut >= 36);
        }
    }
}
