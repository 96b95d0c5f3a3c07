//! The online monitor's state as plain data ([`DenseMonitor::save`]): bytes, read back by
//! [`DenseMonitor::load`] with every field checked.
//!
//! The layout is a sequence of little-endian 64-bit words: a magic word, a version, a
//! fingerprint of the formula, then the monitor's fields (counts before the items they
//! count), and last a checksum (FNV-1a) of the words before it. Reading checks each count against the bytes that are left before it allocates,
//! each time and value for what it may be (finite, increasing, not NaN), each index
//! against what it indexes, and every structure that follows from others (a window's
//! monotone deque, the bounded `until`'s folds) against its recomputation: a state the
//! monitor could not have saved is refused, never run.
//!
//! [`DenseMonitor::save`]: super::DenseMonitor::save
//! [`DenseMonitor::load`]: super::DenseMonitor::load

use std::fmt;

/// "hstldns1": the first word of a saved dense monitor.
pub(crate) const MAGIC: u64 = u64::from_le_bytes(*b"hstldns1");
/// The layout's version.
pub(crate) const VERSION: u64 = 1;

/// Why saved bytes are not a monitor's state.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SavedStateError {
    /// What is wrong, and at which byte.
    pub message: String,
}

impl fmt::Display for SavedStateError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.message)
    }
}

impl std::error::Error for SavedStateError {}

/// Writes words.
#[derive(Default)]
pub(crate) struct Writer {
    pub(crate) bytes: Vec<u8>,
}

impl Writer {
    pub(crate) fn word(&mut self, w: u64) {
        self.bytes.extend_from_slice(&w.to_le_bytes());
    }

    pub(crate) fn count(&mut self, n: usize) {
        self.word(n as u64);
    }

    pub(crate) fn f64(&mut self, x: f64) {
        self.word(x.to_bits());
    }

    pub(crate) fn i128(&mut self, x: i128) {
        let bits = x as u128;
        self.word(bits as u64);
        self.word((bits >> 64) as u64);
    }

    pub(crate) fn opt_f64(&mut self, x: Option<f64>) {
        match x {
            Some(x) => {
                self.word(1);
                self.f64(x);
            }
            None => self.word(0),
        }
    }

    pub(crate) fn opt_i128(&mut self, x: Option<i128>) {
        match x {
            Some(x) => {
                self.word(1);
                self.i128(x);
            }
            None => self.word(0),
        }
    }

    pub(crate) fn points<'a>(&mut self, points: impl ExactSizeIterator<Item = &'a (f64, f64)>) {
        self.count(points.len());
        for &(t, v) in points {
            self.f64(t);
            self.f64(v);
        }
    }
}

/// Reads words, each check naming what it read and where.
pub(crate) struct Reader<'a> {
    bytes: &'a [u8],
    at: usize,
}

impl<'a> Reader<'a> {
    pub(crate) fn new(bytes: &'a [u8]) -> Reader<'a> {
        Reader { bytes, at: 0 }
    }

    /// An error about the word just read (or the one at `at`), `what` naming it.
    pub(crate) fn bad(&self, what: &str) -> SavedStateError {
        SavedStateError {
            message: format!("{what} (byte {} of {})", self.at.saturating_sub(8), self.bytes.len()),
        }
    }

    pub(crate) fn word(&mut self, what: &str) -> Result<u64, SavedStateError> {
        let Some(chunk) = self.bytes.get(self.at..self.at + 8) else {
            return Err(SavedStateError {
                message: format!(
                    "the state ends at byte {} in the middle of {what}: it was cut short",
                    self.bytes.len()
                ),
            });
        };
        self.at += 8;
        let mut w = [0u8; 8];
        w.copy_from_slice(chunk);
        Ok(u64::from_le_bytes(w))
    }

    /// A count of items of `words` words each: no more than the bytes left hold.
    pub(crate) fn count(&mut self, words: usize, what: &str) -> Result<usize, SavedStateError> {
        let n = self.word(what)?;
        let left = (self.bytes.len() - self.at) / 8;
        match usize::try_from(n) {
            Ok(n) if n.saturating_mul(words.max(1)) <= left => Ok(n),
            _ => Err(self.bad(&format!("{what} counts {n} items, more than the state holds"))),
        }
    }

    /// A number up to `max`.
    pub(crate) fn index(&mut self, max: usize, what: &str) -> Result<usize, SavedStateError> {
        let n = self.word(what)?;
        match usize::try_from(n) {
            Ok(n) if n <= max => Ok(n),
            _ => Err(self.bad(&format!("{what} is {n}, more than {max}"))),
        }
    }

    pub(crate) fn flag(&mut self, what: &str) -> Result<bool, SavedStateError> {
        match self.word(what)? {
            0 => Ok(false),
            1 => Ok(true),
            w => Err(self.bad(&format!("{what} is {w}, neither 0 nor 1"))),
        }
    }

    pub(crate) fn f64(&mut self, what: &str) -> Result<f64, SavedStateError> {
        Ok(f64::from_bits(self.word(what)?))
    }

    /// A value: any number but NaN.
    pub(crate) fn value(&mut self, what: &str) -> Result<f64, SavedStateError> {
        let v = self.f64(what)?;
        if v.is_nan() {
            return Err(self.bad(&format!("{what} is NaN")));
        }
        Ok(v)
    }

    /// A time: a finite number.
    pub(crate) fn time(&mut self, what: &str) -> Result<f64, SavedStateError> {
        let t = self.f64(what)?;
        if !t.is_finite() {
            return Err(self.bad(&format!("{what} is {t}, not a finite time")));
        }
        Ok(t)
    }

    pub(crate) fn i128(&mut self, what: &str) -> Result<i128, SavedStateError> {
        let lo = self.word(what)?;
        let hi = self.word(what)?;
        Ok(((u128::from(hi) << 64) | u128::from(lo)) as i128)
    }

    pub(crate) fn opt_value(&mut self, what: &str) -> Result<Option<f64>, SavedStateError> {
        Ok(if self.flag(what)? { Some(self.value(what)?) } else { None })
    }

    pub(crate) fn opt_i128(&mut self, what: &str) -> Result<Option<i128>, SavedStateError> {
        Ok(if self.flag(what)? { Some(self.i128(what)?) } else { None })
    }

    /// Change points: finite times, strictly increasing, values not NaN.
    pub(crate) fn points(&mut self, what: &str) -> Result<Vec<(f64, f64)>, SavedStateError> {
        let n = self.count(2, what)?;
        let mut out = Vec::with_capacity(n);
        for _ in 0..n {
            let t = self.time(what)?;
            let v = self.value(what)?;
            if out.last().is_some_and(|&(p, _)| t <= p) {
                return Err(self.bad(&format!("{what}: the times do not increase")));
            }
            out.push((t, v));
        }
        Ok(out)
    }

    /// Whether every byte was read.
    pub(crate) fn finish(&self) -> Result<(), SavedStateError> {
        if self.at != self.bytes.len() {
            return Err(SavedStateError {
                message: format!(
                    "the state has {} bytes after its end (byte {}): it is not one state",
                    self.bytes.len() - self.at,
                    self.at
                ),
            });
        }
        Ok(())
    }
}

/// The checksum a saved state ends with.
pub(crate) fn sum_of(bytes: &[u8]) -> u64 {
    let mut w = [0u8; 8];
    if let Some(tail) = bytes.len().checked_sub(8).and_then(|k| bytes.get(k..)) {
        w.copy_from_slice(tail);
    }
    u64::from_le_bytes(w)
}

/// Rewrites the checksum that a saved monitor's bytes ([`DenseMonitor::save`]) end with,
/// for a tool (or a test) that changes a state on purpose and wants it read by the
/// structural checks of [`DenseMonitor::load`] rather than refused for its checksum. Bytes
/// shorter than two words are left as they are.
///
/// [`DenseMonitor::save`]: super::DenseMonitor::save
/// [`DenseMonitor::load`]: super::DenseMonitor::load
pub fn resum(bytes: &mut [u8]) {
    if bytes.len() < 16 {
        return;
    }
    let body = bytes.len() - 8;
    let sum = fnv(&bytes[..body]);
    bytes[body..].copy_from_slice(&sum.to_le_bytes());
}

/// FNV-1a, 64 bits.
pub(crate) fn fnv(bytes: &[u8]) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for &b in bytes {
        h ^= u64::from(b);
        h = h.wrapping_mul(0x0100_0000_01b3);
    }
    h
}
