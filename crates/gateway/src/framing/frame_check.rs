//! [`FrameCheck`]: a checksum as a framing carries it, with the octet order of its value.

use crate::checksum::Checksum;
use crate::ByteOrder;

/// A frame's check: which checksum, and the order of its octets on the wire.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FrameCheck {
    /// The checksum.
    pub checksum: Checksum,
    /// Octet order of its value.
    pub order: ByteOrder,
}

impl FrameCheck {
    /// Octets it takes on the wire.
    pub fn len_bytes(&self) -> usize {
        self.checksum.width_bytes()
    }

    /// Appends the check value of `out[from..]` (the octets it covers, already written).
    pub fn append_over(&self, out: &mut Vec<u8>, from: usize) {
        let value = self.checksum.compute(out.get(from..).unwrap_or_default());
        self.order
            .write_uint(u64::from(value), self.len_bytes(), out);
    }

    /// The check octets of `covered`, in the first [`FrameCheck::len_bytes`] octets of the
    /// returned array.
    pub fn octets(&self, covered: &[u8]) -> [u8; 4] {
        let mut octets = [0u8; 4];
        let len = self.len_bytes().min(4);
        self.order.put_uint(
            u64::from(self.checksum.compute(covered)),
            &mut octets[..len],
        );
        octets
    }

    /// Whether `stored` (the check octets received) is the check value of `covered`.
    pub fn verify(&self, covered: &[u8], stored: &[u8]) -> bool {
        stored.len() == self.len_bytes()
            && self.order.read_uint(stored) == u64::from(self.checksum.compute(covered))
    }

    /// Splits a received `frame` (content then check) into its content, if the check holds.
    pub fn strip<'a>(&self, frame: &'a [u8]) -> Option<&'a [u8]> {
        let content_len = frame.len().checked_sub(self.len_bytes())?;
        let (content, stored) = frame.split_at(content_len);
        self.verify(content, stored).then_some(content)
    }
}
