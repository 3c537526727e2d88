//! The sync-and-length encoder.

use super::LengthFraming;
use crate::framing::FramingError;

impl LengthFraming {
    /// Appends one frame: the sync octets, `header` (the octets between sync and length field,
    /// exactly as many as the layout has), the length field, `payload` and the check.
    pub fn encode(
        &self,
        header: &[u8],
        payload: &[u8],
        out: &mut Vec<u8>,
    ) -> Result<(), FramingError> {
        let config = self.config();
        let expected_bytes = config.length.offset_bytes - config.sync.len();
        if header.len() != expected_bytes {
            return Err(FramingError::HeaderLength {
                expected_bytes,
                got_bytes: header.len(),
            });
        }
        let frame_bytes = self.header_len() + payload.len() + self.check_len();
        if frame_bytes > config.max_frame_bytes {
            return Err(FramingError::PayloadTooLong {
                payload_bytes: payload.len(),
                frame_bytes,
                max_bytes: config.max_frame_bytes,
            });
        }
        let width_bytes = config.length.width_bytes;
        let value =
            (payload.len() + self.counted_overhead()) as i128 - i128::from(config.length.adjust);
        if value < 0 || value >> (8 * width_bytes) != 0 {
            return Err(FramingError::LengthDoesNotFit { value, width_bytes });
        }
        let start = out.len();
        out.extend_from_slice(&config.sync);
        out.extend_from_slice(header);
        config
            .length
            .order
            .write_uint(value as u64, width_bytes, out);
        out.extend_from_slice(payload);
        if let Some(check) = &config.check {
            check.append_over(out, start + config.check_from_bytes);
        }
        Ok(())
    }
}
