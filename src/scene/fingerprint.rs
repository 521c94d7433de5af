//! Fingerprints (FNV-1a, 64 bits) of what decides an image: the scene as uploaded, the
//! shaders, a camera. Cache keys are built from them, so a changed scene file or integrator
//! never reuses a stale reference.

/// A running FNV-1a hash: not cryptographic, but any changed byte changes it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Fingerprint(u64);

impl Default for Fingerprint {
    fn default() -> Self {
        Self(0xcbf2_9ce4_8422_2325)
    }
}

impl Fingerprint {
    /// Adds `bytes`, then their length, so that ("ab", "c") and ("a", "bc") differ.
    pub fn bytes(mut self, bytes: &[u8]) -> Self {
        for &b in bytes.iter().chain(&(bytes.len() as u64).to_le_bytes()) {
            self.0 = (self.0 ^ b as u64).wrapping_mul(0x0000_0100_0000_01b3);
        }
        self
    }

    pub fn u64(self, value: u64) -> Self {
        self.bytes(&value.to_le_bytes())
    }

    pub fn f32s(self, values: impl IntoIterator<Item = f32>) -> Self {
        let bytes: Vec<u8> = values.into_iter().flat_map(f32::to_le_bytes).collect();
        self.bytes(&bytes)
    }

    pub fn value(self) -> u64 {
        self.0
    }
}

#[cfg(test)]
mod tests {
    use super::Fingerprint;

    #[test]
    fn any_changed_byte_or_boundary_changes_it() {
        let f = |parts: &[&[u8]]| {
            (parts.iter())
                .fold(Fingerprint::default(), |f, p| f.bytes(p))
                .value()
        };
        assert_eq!(f(&[b"abc"]), f(&[b"abc"]));
        assert_ne!(f(&[b"abc"]), f(&[b"abd"]));
        assert_ne!(f(&[b"ab", b"c"]), f(&[b"a", b"bc"]));
        assert_ne!(f(&[]), f(&[b""]));
    }
}
