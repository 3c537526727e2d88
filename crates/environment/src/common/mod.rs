//! The position-independent part of an environment update — the Earth's orientation, the Sun's
//! and the Moon's geocentric positions — evaluated once per instant for every vehicle of a
//! world (issue 22: "the epoch, the Sun and the Moon are common").
//!
//! These depend only on the simulation time (the vehicles of a fleet share one epoch, checked by
//! the fleet file), so every vehicle's environment model would compute the same bits at the same
//! update instant. A [`CommonCache`] shared by the vehicles' models holds what the first of them
//! computed, and the others read it instead of evaluating the precession-nutation (~1.5 µs) and
//! the lunar series (~2 µs) again; the magnetic field, the density, the wind and the shadow
//! factor depend on the vehicle's position and stay per vehicle.
//!
//! # Why sharing cannot change a result
//! A cache entry is the output of the same function of (time, which parts) that a model would
//! evaluate itself, so a hit and a miss give the same bits, whichever vehicle or thread filled
//! it, and whatever the order the vehicles' workers run in. A reader that finds a slot being
//! written, another instant in it, or other parts, evaluates the parts itself: the cache is only
//! a memo, and nothing waits on it.
//!
//! # The slots
//! [`SLOTS`] entries, indexed by a hash of the instant. Each is a sequence lock made of atomics
//! (no lock, no allocation, no `unsafe`): a writer claims the slot by moving its sequence number
//! from even to odd (a failed claim just skips the store), writes the words, and makes it even
//! again with release ordering; a reader loads the sequence number (acquire), the words, an
//! acquire fence, and the sequence number again, and uses the words only if both loads saw the
//! same even number (the protocol of Boehm, "Can Seqlocks Get Along With Programming Language
//! Memory Models?", MSPC 2012, §3, with every datum an atomic).

use std::sync::atomic::{fence, AtomicU64, Ordering};

use nalgebra::{Matrix3, Vector3};

use super::earth_rotation::EarthFrame;

/// Which parts of a [`Common`] an environment model needs (and a cache entry holds).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Parts {
    /// The Earth-fixed frame (for the magnetic field and the atmosphere).
    pub earth: bool,
    /// The Sun's position.
    pub sun: bool,
    /// The Moon's position.
    pub moon: bool,
}

impl Parts {
    fn bits(self) -> u64 {
        u64::from(self.earth) | u64::from(self.sun) << 1 | u64::from(self.moon) << 2
    }
}

/// The position-independent part of an update at one instant; the parts not asked for are
/// zero.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Common {
    /// The Earth-fixed frame, if [`Parts::earth`].
    pub earth: EarthFrame,
    /// \[m\] r_Sun/⊕, N components, if [`Parts::sun`].
    pub r_sun_n_m: Vector3<f64>,
    /// \[m\] r_Moon/⊕, N components, if [`Parts::moon`].
    pub r_moon_n_m: Vector3<f64>,
}

impl Common {
    /// Everything zero (the parts not asked for).
    pub fn zero() -> Self {
        Common {
            earth: EarthFrame {
                dcm_en: Matrix3::zeros(),
                omega_en_n_rad_s: Vector3::zeros(),
                gast_rad: 0.0,
            },
            r_sun_n_m: Vector3::zeros(),
            r_moon_n_m: Vector3::zeros(),
        }
    }
}

/// Words of a slot's payload: the instant, the parts, then 9 + 3 + 1 + 3 + 3 values.
const WORDS: usize = 2 + 19;

/// Number of slots: the vehicles of a world update at the same instants, so a handful of
/// instants in flight at once (their workers run up to one update ahead) is all a slot set needs
/// to hold.
pub const SLOTS: usize = 8;

#[derive(Debug)]
struct Slot {
    /// Even: stable; odd: being written.
    seq: AtomicU64,
    words: [AtomicU64; WORDS],
}

/// The memo of [`Common`] values that the environment models of one world share (module docs).
#[derive(Debug)]
pub struct CommonCache {
    slots: [Slot; SLOTS],
    hits: AtomicU64,
    misses: AtomicU64,
}

impl Default for CommonCache {
    fn default() -> Self {
        Self::new()
    }
}

fn to_words(t_sim_ns: u64, parts: Parts, c: &Common) -> [u64; WORDS] {
    let mut w = [0u64; WORDS];
    w[0] = t_sim_ns;
    w[1] = parts.bits();
    let values = c
        .earth
        .dcm_en
        .iter()
        .chain(c.earth.omega_en_n_rad_s.iter())
        .chain(std::iter::once(&c.earth.gast_rad))
        .chain(c.r_sun_n_m.iter())
        .chain(c.r_moon_n_m.iter());
    for (x, v) in w[2..].iter_mut().zip(values) {
        *x = v.to_bits();
    }
    w
}

fn from_words(w: &[u64; WORDS]) -> Common {
    let v = |i: usize| f64::from_bits(w[2 + i]);
    Common {
        earth: EarthFrame {
            dcm_en: Matrix3::from_fn(|r, c| v(c * 3 + r)),
            omega_en_n_rad_s: Vector3::new(v(9), v(10), v(11)),
            gast_rad: v(12),
        },
        r_sun_n_m: Vector3::new(v(13), v(14), v(15)),
        r_moon_n_m: Vector3::new(v(16), v(17), v(18)),
    }
}

impl CommonCache {
    /// An empty cache.
    pub fn new() -> Self {
        Self {
            slots: std::array::from_fn(|_| Slot {
                seq: AtomicU64::new(0),
                words: std::array::from_fn(|_| AtomicU64::new(0)),
            }),
            hits: AtomicU64::new(0),
            misses: AtomicU64::new(0),
        }
    }

    fn slot(&self, t_sim_ns: u64) -> &Slot {
        // Fibonacci hashing: update instants are multiples of a round step, whose low bits
        // are all alike; the top bits of the product spread them.
        let i = (t_sim_ns.wrapping_mul(0x9E37_79B9_7F4A_7C15) >> 61) as usize;
        &self.slots[i % SLOTS]
    }

    /// The entry for `t_sim_ns` and `parts` if a model stored it, else `None` (evaluate it).
    /// Lock-free and allocation-free.
    pub fn get(&self, t_sim_ns: u64, parts: Parts) -> Option<Common> {
        let slot = self.slot(t_sim_ns);
        let seq = slot.seq.load(Ordering::Acquire);
        if seq & 1 == 1 {
            return None;
        }
        let mut w = [0u64; WORDS];
        for (x, cell) in w.iter_mut().zip(&slot.words) {
            *x = cell.load(Ordering::Relaxed);
        }
        fence(Ordering::Acquire);
        if slot.seq.load(Ordering::Relaxed) != seq || w[0] != t_sim_ns || w[1] != parts.bits() {
            return None;
        }
        Some(from_words(&w))
    }

    /// Stores `common`, the entry for `t_sim_ns` and `parts`, unless another writer holds the
    /// slot (then nothing is stored: a later reader evaluates it itself). Lock-free and
    /// allocation-free.
    pub fn put(&self, t_sim_ns: u64, parts: Parts, common: &Common) {
        let slot = self.slot(t_sim_ns);
        let seq = slot.seq.load(Ordering::Relaxed);
        if seq & 1 == 1
            || slot
                .seq
                .compare_exchange(seq, seq + 1, Ordering::Acquire, Ordering::Relaxed)
                .is_err()
        {
            return;
        }
        for (cell, x) in slot.words.iter().zip(to_words(t_sim_ns, parts, common)) {
            cell.store(x, Ordering::Relaxed);
        }
        slot.seq.store(seq + 2, Ordering::Release);
    }

    /// The entry for `t_sim_ns` and `parts`: the stored one, or `evaluate()`'s, which is then
    /// stored for the others. Counts hits and misses.
    #[inline]
    pub fn get_or_evaluate(
        &self,
        t_sim_ns: u64,
        parts: Parts,
        evaluate: impl FnOnce() -> Common,
    ) -> Common {
        if let Some(c) = self.get(t_sim_ns, parts) {
            self.hits.fetch_add(1, Ordering::Relaxed);
            return c;
        }
        self.misses.fetch_add(1, Ordering::Relaxed);
        let c = evaluate();
        self.put(t_sim_ns, parts, &c);
        c
    }

    /// (hits, misses) of [`Self::get_or_evaluate`] so far: with N vehicles updating at the same
    /// instants, about N − 1 hits per miss.
    pub fn counts(&self) -> (u64, u64) {
        (
            self.hits.load(Ordering::Relaxed),
            self.misses.load(Ordering::Relaxed),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn common(k: f64) -> Common {
        Common {
            earth: EarthFrame {
                dcm_en: Matrix3::from_fn(|r, c| k + (3 * r + c) as f64),
                omega_en_n_rad_s: Vector3::new(k, -k, 2.0 * k),
                gast_rad: k * 0.5,
            },
            r_sun_n_m: Vector3::new(1.5e11 * k, 2.0, -3.0),
            r_moon_n_m: Vector3::new(3.8e8, k, -k),
        }
    }

    const ALL: Parts = Parts {
        earth: true,
        sun: true,
        moon: true,
    };

    #[test]
    fn a_stored_entry_comes_back_bit_for_bit_for_its_instant_and_parts_only() {
        let cache = CommonCache::new();
        let t = 300_000_000;
        assert_eq!(cache.get(t, ALL), None);
        let c = common(0.7);
        cache.put(t, ALL, &c);
        assert_eq!(cache.get(t, ALL), Some(c));
        // Another instant in the same slot or other parts: a miss, never a wrong entry.
        assert_eq!(cache.get(t + 1, ALL), None);
        let sun_only = Parts {
            earth: false,
            sun: true,
            moon: false,
        };
        assert_eq!(cache.get(t, sun_only), None);
    }

    #[test]
    fn get_or_evaluate_evaluates_once_per_instant_and_counts() {
        let cache = CommonCache::new();
        let mut evaluations = 0;
        for _vehicle in 0..4 {
            for update in 0..3u64 {
                let t = update * 100_000_000;
                let got = cache.get_or_evaluate(t, ALL, || {
                    evaluations += 1;
                    common(update as f64)
                });
                assert_eq!(got, common(update as f64));
            }
        }
        assert_eq!(evaluations, 3);
        assert_eq!(cache.counts(), (9, 3));
    }

    /// Readers racing a writer on one slot see either a miss or a whole entry, never a torn
    /// one: every word of entry k is derived from k, so a mix of two entries is detectable.
    #[test]
    fn concurrent_readers_never_see_a_torn_entry() {
        let cache = std::sync::Arc::new(CommonCache::new());
        let t = 42;
        let writer = {
            let cache = cache.clone();
            std::thread::spawn(move || {
                for k in 0..20_000 {
                    cache.put(t, ALL, &common(f64::from(k)));
                }
            })
        };
        let mut seen = 0;
        while !writer.is_finished() || seen == 0 {
            if let Some(c) = cache.get(t, ALL) {
                let k = c.earth.gast_rad * 2.0;
                assert_eq!(c, common(k), "torn entry");
                seen += 1;
            }
        }
        writer.join().unwrap();
        assert!(seen > 0);
    }
}
