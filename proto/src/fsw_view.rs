//! A [`FswMsg`] read in place, without allocating: the server judges every sample of the flight
//! code's telemetry on a Zenoh thread that, in lockstep's direct hand-off, also steps the frames,
//! so the check of an accepted sample must allocate nothing (`tests/server_alloc.rs`).
//!
//! [`view_fsw`] accepts exactly the bytes [`crate::decode_fsw`] accepts, with the same values,
//! and refuses the others with the class of [`crate::DecodeError`] that `decode_fsw` gives
//! (`tests/proptests.rs` checks both on arbitrary, truncated and bit-damaged samples). The
//! checks, in `decode`'s order: at most [`crate::MAX_MESSAGE_BYTES`]; the protocol version; the length
//! the value count at [`FSW_VALUES_COUNT_OFFSET`] implies (the count within
//! [`MAX_FSW_VALUES`]) against the buffer; `event_count` within [`MAX_FSW_EVENTS`]; then
//! `q_est_bn`, `q_target_rn` and `att_var_b_rad2` finite, in wire order (proto/README.md,
//! "FswMsg").

use crate::view::{f64_at, header_at, size_and_version, u16_at, u32_at, u64_at, ViewError};
use crate::{
    FswMsg, Header, FSW_FIXED_LEN, FSW_VALUES_COUNT_OFFSET, MAX_FSW_EVENTS, MAX_FSW_VALUES,
};

/// A flight-code telemetry sample, read in place (the fields of [`FswMsg`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FswView<'a> {
    /// Its header.
    pub header: Header,
    /// Which optional fields are set ([`crate::fsw_flags`]).
    pub flags: u8,
    /// The mode index (with MODE).
    pub mode: u32,
    /// The attitude estimate, scalar first (with ESTIMATE).
    pub q_est_bn: [f64; 4],
    /// The target attitude, scalar first (with TARGET).
    pub q_target_rn: [f64; 4],
    /// \[rad²\] the estimate's error variances about the body axes (with COVARIANCE).
    pub att_var_b_rad2: [f64; 3],
    /// How many of `events` are set (≤ [`MAX_FSW_EVENTS`]).
    pub event_count: u8,
    /// The event indices; the first `event_count` are the sample's.
    pub events: [u16; MAX_FSW_EVENTS],
    /// The value words, 8 little-endian bytes each.
    values: &'a [u8],
}

impl FswView<'_> {
    /// The sample's event indices (the first `event_count` of `events`).
    pub fn event_indices(&self) -> &[u16] {
        &self.events[..usize::from(self.event_count).min(MAX_FSW_EVENTS)]
    }

    /// How many value words it carries.
    pub fn values_len(&self) -> usize {
        self.values.len() / 8
    }

    /// Value word `i` (`None` beyond [`Self::values_len`]).
    pub fn value_word(&self, i: usize) -> Option<u64> {
        u64_at(self.values, i.checked_mul(8)?)
    }

    /// The owned message (allocates): for tests and tools.
    pub fn to_owned_msg(&self) -> FswMsg {
        FswMsg {
            header: self.header,
            flags: self.flags,
            mode: self.mode,
            q_est_bn: self.q_est_bn,
            q_target_rn: self.q_target_rn,
            att_var_b_rad2: self.att_var_b_rad2,
            event_count: self.event_count,
            events: self.events,
            values: (0..self.values_len())
                .filter_map(|i| self.value_word(i))
                .collect(),
        }
    }
}

/// `N` f64s from `at`, and whether every one is finite.
fn floats<const N: usize>(b: &[u8], at: usize) -> Result<([f64; N], bool), ViewError> {
    let mut out = [0.0; N];
    for (k, x) in out.iter_mut().enumerate() {
        *x = f64_at(b, at + 8 * k).ok_or(ViewError::Malformed)?;
    }
    Ok((out, out.iter().all(|x| x.is_finite())))
}

/// Reads a [`FswMsg`] in place (module docs). Allocates nothing.
pub fn view_fsw(bytes: &[u8]) -> Result<FswView<'_>, ViewError> {
    let found = size_and_version(bytes)?;
    let n = u64_at(bytes, FSW_VALUES_COUNT_OFFSET).ok_or(ViewError::Malformed)?;
    let n = usize::try_from(n)
        .ok()
        .filter(|n| *n <= MAX_FSW_VALUES)
        .ok_or(ViewError::Malformed)?;
    if bytes.len() != FSW_FIXED_LEN + 8 * n {
        return Err(ViewError::Malformed);
    }
    let event_count = bytes[123];
    if usize::from(event_count) > MAX_FSW_EVENTS {
        return Err(ViewError::Malformed);
    }
    let header = header_at(bytes, found)?;
    let (q_est_bn, est_ok) = floats::<4>(bytes, 35)?;
    let (q_target_rn, target_ok) = floats::<4>(bytes, 67)?;
    let (att_var_b_rad2, var_ok) = floats::<3>(bytes, 99)?;
    if !(est_ok && target_ok && var_ok) {
        return Err(ViewError::NonFinite);
    }
    let mut events = [0u16; MAX_FSW_EVENTS];
    for (k, e) in events.iter_mut().enumerate() {
        *e = u16_at(bytes, 124 + 2 * k).ok_or(ViewError::Malformed)?;
    }
    Ok(FswView {
        header,
        flags: bytes[30],
        mode: u32_at(bytes, 31).ok_or(ViewError::Malformed)?,
        q_est_bn,
        q_target_rn,
        att_var_b_rad2,
        event_count,
        events,
        values: &bytes[FSW_FIXED_LEN..],
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{decode_fsw, encode, fsw_flags};

    fn sample() -> FswMsg {
        let mut m = FswMsg {
            header: Header::new(7, 42, 420_000_000, 9),
            flags: fsw_flags::MODE | fsw_flags::ESTIMATE | fsw_flags::COVARIANCE,
            mode: 3,
            q_est_bn: [0.5, 0.5, -0.5, 0.5],
            q_target_rn: [1.0, 0.0, 0.0, 0.0],
            att_var_b_rad2: [1e-8, 2e-8, 3e-8],
            event_count: 2,
            values: vec![1.5f64.to_bits(), (-3i64) as u64, 1],
            ..FswMsg::default()
        };
        m.events[..2].copy_from_slice(&[4, 1]);
        m
    }

    /// The view reads every field as `decode_fsw` does, at the offsets of proto/README.md.
    #[test]
    fn a_valid_sample_reads_as_it_decodes() {
        let bytes = encode(&sample());
        let v = view_fsw(&bytes).unwrap();
        assert_eq!(v.to_owned_msg(), decode_fsw(&bytes).unwrap());
        assert_eq!(v.event_indices(), &[4, 1]);
        assert_eq!(v.values_len(), 3);
        assert_eq!(v.value_word(1), Some((-3i64) as u64));
        assert_eq!(v.value_word(3), None);
    }

    /// Each way to break a sample is refused with decode's class.
    #[test]
    fn damaged_samples_are_refused_like_decode_refuses_them() {
        let good = encode(&sample());
        let class = |b: &[u8]| {
            (
                view_fsw(b).err(),
                decode_fsw(b).err().map(|e| ViewError::of(&e)),
            )
        };
        let mut cases: Vec<Vec<u8>> = Vec::new();
        cases.push(good[..good.len() - 1].to_vec()); // truncated
        cases.push([good.as_slice(), &[0]].concat()); // trailing byte
        let mut v = good.clone();
        v[0] ^= 1; // version
        cases.push(v);
        let mut v = good.clone();
        v[123] = 9; // event_count
        cases.push(v);
        let mut v = good.clone();
        v[140..148].copy_from_slice(&257u64.to_le_bytes()); // value count
        cases.push(v);
        let mut v = good.clone();
        v[35..43].copy_from_slice(&f64::NAN.to_le_bytes()); // q_est_bn[0]
        cases.push(v);
        let mut v = good.clone();
        v[115..123].copy_from_slice(&f64::INFINITY.to_le_bytes()); // att_var_b_rad2[2]
        cases.push(v);
        cases.push(good[..100].to_vec());
        cases.push(Vec::new());
        for (i, b) in cases.iter().enumerate() {
            let (view, decode) = class(b);
            assert!(view.is_some(), "case {i}: accepted");
            assert_eq!(view, decode, "case {i}");
        }
    }
}
