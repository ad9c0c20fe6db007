//! The 64-bit FNV-1a hash: scene digests and checkpoint checksums.

/// The 64-bit FNV-1a hash, fed eight bytes at a time.
pub(crate) struct Fnv(pub(crate) u64);

impl Default for Fnv {
    fn default() -> Self {
        Fnv(0xcbf2_9ce4_8422_2325)
    }
}

impl Fnv {
    /// Hashes `word`'s eight bytes, least significant first.
    pub(crate) fn add(&mut self, word: u64) {
        self.bytes(&word.to_le_bytes());
    }

    /// Hashes `bytes`.
    pub(crate) fn bytes(&mut self, bytes: &[u8]) {
        for &byte in bytes {
            self.0 = (self.0 ^ u64::from(byte)).wrapping_mul(0x0000_0100_0000_01b3);
        }
    }
}
