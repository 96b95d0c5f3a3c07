//! The digest `policy.json`'s `checksum` holds: FNV-1a over 64 bits, written into as an
//! [`std::io::Write`] so that a document is digested as it is serialized, never held.
//! It catches a document edited after it was written; it is no signature (anyone can
//! compute it again).

/// FNV-1a (64 bits) over the bytes written into it.
#[derive(Clone, Copy, Debug)]
pub struct Digest(u64);

const OFFSET: u64 = 0xcbf2_9ce4_8422_2325;
const PRIME: u64 = 0x0000_0100_0000_01b3;

impl Digest {
    /// The digest of no bytes.
    pub fn new() -> Digest {
        Digest(OFFSET)
    }

    /// Adds `bytes`.
    pub fn bytes(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 = (self.0 ^ u64::from(b)).wrapping_mul(PRIME);
        }
    }

    /// The digest as `policy.json` writes it: 16 lowercase hexadecimal digits.
    pub fn hex(&self) -> String {
        format!("{:016x}", self.0)
    }
}

impl Default for Digest {
    fn default() -> Digest {
        Digest::new()
    }
}

impl std::io::Write for Digest {
    fn write(&mut self, bytes: &[u8]) -> std::io::Result<usize> {
        self.bytes(bytes);
        Ok(bytes.len())
    }

    fn flush(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_published_fnv1a_values() {
        // The FNV reference values for "" and "a" (64-bit FNV-1a).
        assert_eq!(Digest::new().hex(), "cbf29ce484222325");
        let mut d = Digest::new();
        d.bytes(b"a");
        assert_eq!(d.hex(), "af63dc4c8601ec8c");
    }
}
