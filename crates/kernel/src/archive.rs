//! The state of a run as bytes, for checkpoints: one listing per component, read in both
//! directions.
//!
//! A component lists its *mutable* state once, in [`Archived::archive`] (or a method of the same
//! shape on a trait object), field by field: `a.put(&mut self.kappa); a.put(&mut self.rng_words)`.
//! The same listing saves (an [`Archive::saving`] appends each field's bytes) and restores (an
//! [`Archive::loading`] overwrites each field from the bytes), so the two directions cannot
//! drift apart. What a component was built with (its configuration, its constants) is not listed:
//! a checkpoint is restored into a run freshly built from a compatible configuration.
//!
//! Components group their fields in named [`sections`](Archive::section), each carrying its byte
//! length, so a restore into a differently shaped run stops at the first section whose name or
//! length differs and says which one. A failed read does not panic and does not return early:
//! the first error is kept ([`Archive::finish`]), later reads leave their fields alone, and the
//! caller discards the half-restored run.
//!
//! # Encoding
//! Little-endian, fixed width: `u8`, `bool` (0 or 1), `u32`, `u64`; `f64` as its IEEE-754 bits
//! (so every value, NaN payloads included, comes back bit for bit); `Option<T>` as a `u8` tag (0
//! none, 1 some) then `T`; a length as a `u64`; a section as its name (`u16` length, UTF-8), its
//! body's length (`u64`), then the body.

use nalgebra::{Matrix3, Vector2, Vector3, Vector4};

/// Why a restore stopped.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum ArchiveError {
    /// The bytes ended inside a field.
    #[error("{at}: the state ends early (needed {needed} more bytes)")]
    Truncated {
        /// The section path where it happened.
        at: String,
        /// Bytes missing.
        needed: usize,
    },
    /// A section has another name than this run expects at that place.
    #[error("{at}: the checkpoint has section {found:?} where this run has {expected:?}")]
    Section {
        /// The enclosing section path.
        at: String,
        /// What the run lists.
        expected: String,
        /// What the checkpoint holds.
        found: String,
    },
    /// A section's body is longer or shorter than this run's listing of it.
    #[error("{at}: the checkpoint's section holds {found} bytes, this run's holds {expected}")]
    SectionLength {
        /// The section path.
        at: String,
        /// Bytes this run's listing read.
        expected: u64,
        /// Bytes the checkpoint holds.
        found: u64,
    },
    /// A count differs (sensors, vehicles, a buffer's length, …).
    #[error("{at}: the checkpoint has {found} {what}, this run has {expected}")]
    Count {
        /// The section path.
        at: String,
        /// What is counted.
        what: &'static str,
        /// This run's count.
        expected: u64,
        /// The checkpoint's.
        found: u64,
    },
    /// A byte that is not a valid tag or bool.
    #[error("{at}: {what} is {found}, not a valid value")]
    Invalid {
        /// The section path.
        at: String,
        /// What was read.
        what: &'static str,
        /// The byte found.
        found: u64,
    },
    /// Bytes left over after the last section.
    #[error("the checkpoint's state has {0} bytes after the last section")]
    Trailing(usize),
}

enum Mode<'a> {
    Save(&'a mut Vec<u8>),
    Load { bytes: &'a [u8], pos: usize },
}

/// A save or a restore in progress (see the module docs).
pub struct Archive<'a> {
    mode: Mode<'a>,
    /// The open sections' names, outermost first (for errors).
    path: Vec<String>,
    error: Option<ArchiveError>,
}

impl std::fmt::Debug for Archive<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Archive")
            .field("saving", &self.is_saving())
            .field("path", &self.path)
            .field("error", &self.error)
            .finish()
    }
}

impl<'a> Archive<'a> {
    /// An archive that appends every listed field to `out`.
    pub fn saving(out: &'a mut Vec<u8>) -> Self {
        Self {
            mode: Mode::Save(out),
            path: Vec::new(),
            error: None,
        }
    }

    /// An archive that overwrites every listed field from `bytes`.
    pub fn loading(bytes: &'a [u8]) -> Self {
        Self {
            mode: Mode::Load { bytes, pos: 0 },
            path: Vec::new(),
            error: None,
        }
    }

    /// Whether this archive saves (lists write) rather than restores.
    pub fn is_saving(&self) -> bool {
        matches!(self.mode, Mode::Save(_))
    }

    /// Whether a restore has failed (every later read is skipped).
    pub fn failed(&self) -> bool {
        self.error.is_some()
    }

    /// The first error; for a restore, also an error if bytes are left after the last field.
    pub fn finish(self) -> Result<(), ArchiveError> {
        if let Some(e) = self.error {
            return Err(e);
        }
        match self.mode {
            Mode::Load { bytes, pos } if pos < bytes.len() => {
                Err(ArchiveError::Trailing(bytes.len() - pos))
            }
            _ => Ok(()),
        }
    }

    fn at(&self) -> String {
        if self.path.is_empty() {
            "state".to_string()
        } else {
            self.path.join(" / ")
        }
    }

    /// Records `e` unless an earlier error is kept.
    pub fn fail(&mut self, e: ArchiveError) {
        if self.error.is_none() {
            self.error = Some(e);
        }
    }

    /// Saves or restores `N` raw bytes.
    fn bytes<const N: usize>(&mut self, v: &mut [u8; N]) {
        match &mut self.mode {
            Mode::Save(out) => out.extend_from_slice(v),
            Mode::Load { bytes, pos } => {
                if self.error.is_some() {
                    return;
                }
                match bytes.get(*pos..*pos + N) {
                    Some(b) => {
                        v.copy_from_slice(b);
                        *pos += N;
                    }
                    None => {
                        let needed = *pos + N - bytes.len();
                        let at = self.at();
                        self.fail(ArchiveError::Truncated { at, needed });
                    }
                }
            }
        }
    }

    /// Saves or restores one field.
    #[inline]
    pub fn put<T: Archived + ?Sized>(&mut self, v: &mut T) {
        v.archive(self);
    }

    /// Saves or restores a count that must be the same in the checkpoint and in this run
    /// (the number of sensors, a fixed buffer's length); a different count stops the restore.
    pub fn expect_count(&mut self, what: &'static str, expected: usize) {
        let mut n = expected as u64;
        self.put(&mut n);
        if !self.failed() && n != expected as u64 {
            let at = self.at();
            self.fail(ArchiveError::Count {
                at,
                what,
                expected: expected as u64,
                found: n,
            });
        }
    }

    /// Saves or restores a length that may differ from this run's (a queue's fill): on a restore
    /// `len` becomes the checkpoint's, up to `max` (a larger one stops the restore).
    pub fn length(&mut self, what: &'static str, len: &mut usize, max: usize) {
        let mut n = *len as u64;
        self.put(&mut n);
        if self.failed() {
            return;
        }
        if n > max as u64 {
            let at = self.at();
            self.fail(ArchiveError::Count {
                at,
                what,
                expected: max as u64,
                found: n,
            });
            return;
        }
        *len = n as usize;
    }

    /// Saves or restores a run of bytes of any length up to `max` (an encoded message): its
    /// length, then the bytes.
    pub fn blob(&mut self, what: &'static str, bytes: &mut Vec<u8>, max: usize) {
        let mut n = bytes.len();
        self.length(what, &mut n, max);
        if self.failed() {
            return;
        }
        bytes.resize(n, 0);
        for b in bytes.iter_mut() {
            self.put(b);
        }
    }

    /// Records that a value read back is not one this run can hold (`what`, with the
    /// offending number).
    pub fn invalid(&mut self, what: &'static str, found: u64) {
        let at = self.at();
        self.fail(ArchiveError::Invalid { at, what, found });
    }

    /// Lists `body` inside a section called `name`: saved as its name and byte length; on a
    /// restore, the name must match and `body` must read exactly the section's bytes.
    pub fn section(&mut self, name: &str, body: impl FnOnce(&mut Self)) {
        if self.failed() {
            return;
        }
        let mut name_len = name.len().min(u16::MAX as usize) as u16;
        match &mut self.mode {
            Mode::Save(out) => {
                out.extend_from_slice(&name_len.to_le_bytes());
                out.extend_from_slice(&name.as_bytes()[..name_len as usize]);
                let len_at = out.len();
                out.extend_from_slice(&0u64.to_le_bytes());
                self.path.push(name.to_string());
                body(self);
                self.path.pop();
                if let Mode::Save(out) = &mut self.mode {
                    let body_len = (out.len() - len_at - 8) as u64;
                    out[len_at..len_at + 8].copy_from_slice(&body_len.to_le_bytes());
                }
            }
            Mode::Load { .. } => {
                self.put(&mut name_len);
                let mut found = vec![0u8; name_len as usize];
                for b in &mut found {
                    self.put(b);
                }
                let mut body_len = 0u64;
                self.put(&mut body_len);
                if self.failed() {
                    return;
                }
                let found = String::from_utf8_lossy(&found).into_owned();
                if found != name {
                    let at = self.at();
                    self.fail(ArchiveError::Section {
                        at,
                        expected: name.to_string(),
                        found,
                    });
                    return;
                }
                let start = self.position();
                self.path.push(name.to_string());
                body(self);
                let read = (self.position() - start) as u64;
                if !self.failed() && read != body_len {
                    let at = self.at();
                    self.fail(ArchiveError::SectionLength {
                        at,
                        expected: read,
                        found: body_len,
                    });
                }
                self.path.pop();
            }
        }
    }

    fn position(&self) -> usize {
        match &self.mode {
            Mode::Save(out) => out.len(),
            Mode::Load { pos, .. } => *pos,
        }
    }
}

/// A value whose bits an [`Archive`] saves and restores.
pub trait Archived {
    /// Lists this value's mutable state (see the module docs).
    fn archive(&mut self, a: &mut Archive<'_>);
}

macro_rules! archived_le {
    ($($t:ty),*) => {$(
        impl Archived for $t {
            #[inline]
            fn archive(&mut self, a: &mut Archive<'_>) {
                let mut b = self.to_le_bytes();
                a.bytes(&mut b);
                *self = <$t>::from_le_bytes(b);
            }
        }
    )*};
}
archived_le!(u8, u16, u32, u64, u128, i64);

impl Archived for f64 {
    #[inline]
    fn archive(&mut self, a: &mut Archive<'_>) {
        let mut bits = self.to_bits();
        a.put(&mut bits);
        *self = f64::from_bits(bits);
    }
}

impl Archived for bool {
    fn archive(&mut self, a: &mut Archive<'_>) {
        let mut b = u8::from(*self);
        a.put(&mut b);
        if b > 1 {
            let at = a.at();
            a.fail(ArchiveError::Invalid {
                at,
                what: "a bool",
                found: b.into(),
            });
            return;
        }
        *self = b == 1;
    }
}

impl<T: Archived + Default> Archived for Option<T> {
    fn archive(&mut self, a: &mut Archive<'_>) {
        let mut tag = u8::from(self.is_some());
        a.put(&mut tag);
        match tag {
            0 => *self = None,
            1 => {
                let v = self.get_or_insert_with(T::default);
                a.put(v);
            }
            found => {
                let at = a.at();
                a.fail(ArchiveError::Invalid {
                    at,
                    what: "an option tag",
                    found: found.into(),
                });
            }
        }
    }
}

impl<T: Archived> Archived for [T] {
    /// The elements in order; the length is this run's (a fixed-size buffer).
    fn archive(&mut self, a: &mut Archive<'_>) {
        for v in self {
            a.put(v);
        }
    }
}

impl<T: Archived, const N: usize> Archived for [T; N] {
    fn archive(&mut self, a: &mut Archive<'_>) {
        a.put(&mut self[..]);
    }
}

macro_rules! archived_matrix {
    ($($t:ty),*) => {$(
        impl Archived for $t {
            /// Its elements in storage (column-major) order.
            fn archive(&mut self, a: &mut Archive<'_>) {
                a.put(self.as_mut_slice());
            }
        }
    )*};
}
archived_matrix!(Vector2<f64>, Vector3<f64>, Vector4<f64>, Matrix3<f64>);

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Debug, Default, PartialEq, Clone)]
    struct Thing {
        x: f64,
        n: u64,
        on: Option<u64>,
        flag: bool,
        v: Vector3<f64>,
    }

    impl Archived for Thing {
        fn archive(&mut self, a: &mut Archive<'_>) {
            a.section("thing", |a| {
                a.put(&mut self.x);
                a.put(&mut self.n);
                a.put(&mut self.on);
                a.put(&mut self.flag);
                a.put(&mut self.v);
            });
        }
    }

    fn sample() -> Thing {
        Thing {
            x: f64::from_bits(0x7ff8_dead_beef_0001), // a NaN with a payload
            n: u64::MAX - 3,
            on: Some(42),
            flag: true,
            v: Vector3::new(-0.0, 1e-300, 3.5),
        }
    }

    #[test]
    fn a_restore_gives_back_every_bit() {
        let mut t = sample();
        let mut bytes = Vec::new();
        let mut a = Archive::saving(&mut bytes);
        a.put(&mut t);
        a.finish().unwrap();
        // name (2 + 5) + length 8 + x 8 + n 8 + option 1 + 8 + bool 1 + vector 24
        assert_eq!(bytes.len(), 7 + 8 + 8 + 8 + 9 + 1 + 24);
        let mut back = Thing::default();
        let mut a = Archive::loading(&bytes);
        a.put(&mut back);
        a.finish().unwrap();
        assert_eq!(back.x.to_bits(), t.x.to_bits());
        assert_eq!(back.v[0].to_bits(), (-0.0f64).to_bits());
        assert_eq!((back.n, back.on, back.flag), (t.n, t.on, t.flag));
    }

    #[test]
    fn a_short_or_renamed_or_resized_state_is_refused_with_its_place() {
        let mut bytes = Vec::new();
        Archive::saving(&mut bytes).put(&mut sample());
        // Truncated inside the vector.
        let mut a = Archive::loading(&bytes[..bytes.len() - 3]);
        a.put(&mut Thing::default());
        let e = a.finish().unwrap_err();
        assert_eq!(
            e,
            ArchiveError::Truncated {
                at: "thing".into(),
                needed: 3
            }
        );
        // Another name.
        let mut renamed = bytes.clone();
        renamed[2] = b'T';
        let mut a = Archive::loading(&renamed);
        a.put(&mut Thing::default());
        let e = a.finish().unwrap_err().to_string();
        assert!(e.contains("\"Thing\"") && e.contains("\"thing\""), "{e}");
        // A listing that reads less than the section holds (a field removed).
        let mut a = Archive::loading(&bytes);
        a.section("thing", |a| a.put(&mut 0.0f64));
        let e = a.finish().unwrap_err();
        assert_eq!(
            e,
            ArchiveError::SectionLength {
                at: "thing".into(),
                expected: 8,
                found: 50
            }
        );
        // Trailing bytes.
        let mut longer = bytes.clone();
        longer.push(0);
        let mut a = Archive::loading(&longer);
        a.put(&mut Thing::default());
        assert_eq!(a.finish(), Err(ArchiveError::Trailing(1)));
        // A bool that is neither 0 nor 1.
        let mut bad = bytes.clone();
        let bool_at = 7 + 8 + 8 + 8 + 9;
        bad[bool_at] = 2;
        let mut a = Archive::loading(&bad);
        a.put(&mut Thing::default());
        assert!(matches!(a.finish(), Err(ArchiveError::Invalid { .. })));
    }

    #[test]
    fn counts_and_lengths_are_checked() {
        let mut bytes = Vec::new();
        let mut a = Archive::saving(&mut bytes);
        a.expect_count("sensors", 3);
        let mut len = 5usize;
        a.length("queued samples", &mut len, 8);
        a.finish().unwrap();
        let mut a = Archive::loading(&bytes);
        a.expect_count("sensors", 4);
        let e = a.finish().unwrap_err().to_string();
        assert_eq!(e, "state: the checkpoint has 3 sensors, this run has 4");
        let mut a = Archive::loading(&bytes);
        a.expect_count("sensors", 3);
        let mut len = 0usize;
        a.length("queued samples", &mut len, 4);
        assert!(a.finish().is_err());
        let mut a = Archive::loading(&bytes);
        a.expect_count("sensors", 3);
        a.length("queued samples", &mut len, 8);
        a.finish().unwrap();
        assert_eq!(len, 5);
    }
}
