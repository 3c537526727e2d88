//! The flight code's own telemetry streams of `flexdyn_fsw_*` (FswMsg, protocol 10): the Rust
//! client's [`flexdyn_proto::client::fsw`] (the served declaration of a stream, its samples
//! filled in by name with every refusal the server would make, and their publisher) with the
//! C library's return codes and C's `int` bools. A stream handle wraps an [`FswStream`].

use std::ffi::c_int;

pub use flexdyn_proto::client::fsw::{FswDeclaration, FswError, FswSampler, FswStream};

use crate::error::{Code, Error};

impl From<FswError> for Error {
    /// The code the header documents: [`Code::Argument`] for a stream the configuration does
    /// not declare and for a wrong argument (an undeclared name, another type or length, a
    /// non-finite f64, another spacecraft's stamp, a ninth event), [`Code::Usage`] for a call
    /// out of order (no sample begun, a tick not after the last published, a sample
    /// incomplete at publish), [`Code::Config`] for a configuration that cannot be read,
    /// [`Code::Zenoh`]; the message is the Rust client's, naming the stream and the field.
    fn from(e: FswError) -> Self {
        let code = match &e {
            FswError::NoStream { .. } | FswError::Sample { .. } => Code::Argument,
            FswError::Order { .. } => Code::Usage,
            FswError::Config(_) => Code::Config,
            FswError::Zenoh { .. } => Code::Zenoh,
            _ => Code::Internal,
        };
        Self::new(code, e.to_string())
    }
}

/// `flexdyn_fsw_set_bool`: bool value `name` of the sample begun, from C `int`s (0 is false,
/// anything else true).
pub fn set_bools(sampler: &mut FswSampler, name: &str, v: &[c_int]) -> Result<(), FswError> {
    sampler.bools_iter(name, v.iter().map(|&x| x != 0))
}

#[cfg(test)]
mod tests {
    use super::*;
    use flexdyn_proto::{decode_fsw, Header, MAX_FSW_EVENTS};

    /// `clients/c/tests/fsw.c`'s stream, after one without anything.
    const TOML: &str = r#"
[[fsw_streams]]
name = "empty"
[[fsw_streams]]
name = "acs"
modes = ["detumble", "point"]
events = [{ name = "gyro_fault", severity = "error" }]
values = [{ name = "h_b_nms", type = "f64", len = 3 }, { name = "flags", type = "i64" },
          { name = "ok", type = "bool" }]
"#;

    fn sampler(stream: &str) -> FswSampler {
        FswSampler::new(FswDeclaration::from_config_toml(TOML, stream).unwrap(), 7)
    }

    fn stamp(tick: u64) -> Header {
        Header::new(7, tick, tick * 10_000_000, 99)
    }

    /// The code and message `flexdyn_fsw_*` return for `r`'s error.
    fn refused<T: std::fmt::Debug>(r: Result<T, FswError>) -> (Code, String) {
        let e = Error::from(r.unwrap_err());
        (e.code, e.message)
    }

    #[test]
    fn an_undeclared_stream_is_an_argument_error_naming_the_declared_ones() {
        let (code, m) = refused(FswDeclaration::from_config_toml(TOML, "gnc"));
        assert_eq!(code, Code::Argument);
        assert!(
            m.contains("no [[fsw_streams]] named \"gnc\"")
                && m.ends_with("(declared: \"empty\", \"acs\")"),
            "{m}"
        );
        let (code, m) = refused(FswDeclaration::from_config_toml("[simulation]\n", "acs"));
        assert_eq!(code, Code::Argument);
        assert!(m.ends_with("(declared: none)"), "{m}");
        assert_eq!(
            refused(FswDeclaration::from_config_toml("x = [", "acs")).0,
            Code::Config
        );
        let zero =
            "[[fsw_streams]]\nname = \"z\"\nvalues = [{ name = \"v\", type = \"i64\", len = 0 }]";
        assert_eq!(
            refused(FswDeclaration::from_config_toml(zero, "z")).0,
            Code::Config
        );
    }

    #[test]
    fn a_sample_from_c_decodes_to_the_words_declared() {
        let mut s = sampler("acs");
        for (tick, ok) in [(4u64, 7), (5, 0)] {
            s.begin_stamped(&stamp(tick)).unwrap();
            s.mode("point").unwrap();
            s.event("gyro_fault").unwrap();
            s.f64s("h_b_nms", &[0.5, -1.0, 0.25]).unwrap();
            s.i64s("flags", &[-3]).unwrap();
            set_bools(&mut s, "ok", &[ok]).unwrap();
            let m = decode_fsw(s.encode().unwrap()).unwrap();
            s.published();
            // Stamped from the server's header, numbered by the stream.
            assert_eq!(m.header, Header::new(7, tick, tick * 10_000_000, tick - 4));
            assert_eq!((m.mode, m.event_indices()), (1, &[0u16][..]));
            // Any int but 0 is true.
            assert_eq!(m.values[3..], [(-3i64) as u64, u64::from(ok != 0)]);
        }
        let mut empty = sampler("empty");
        empty.begin_stamped(&stamp(0)).unwrap();
        let m = decode_fsw(empty.encode().unwrap()).unwrap();
        assert_eq!((m.flags, m.values.len()), (0, 0));
    }

    #[test]
    fn refusals_carry_the_codes_the_header_documents_and_name_stream_and_field() {
        let mut s = sampler("acs");
        assert_eq!(
            refused(s.mode("point")),
            (
                Code::Usage,
                "stream `acs`: no sample begun (call begin first)".to_owned()
            )
        );
        let (code, m) = refused(s.begin_stamped(&Header::new(8, 1, 0, 0)));
        assert_eq!(code, Code::Argument);
        assert!(m.contains("spacecraft_id is 8, the server's is 7"), "{m}");
        s.begin_stamped(&stamp(1)).unwrap();
        let cases = [
            (refused(s.mode("safe")), "\"safe\""),
            (refused(s.event("sun_lost")), "\"sun_lost\""),
            (
                refused(set_bools(&mut s, "sun_valid", &[1])),
                "\"sun_valid\"",
            ),
            (refused(s.f64s("flags", &[1.0])), "`flags` is i64, not f64"),
            (
                refused(s.f64s("h_b_nms", &[1.0, 2.0])),
                "`h_b_nms` has 3 elements, got 2",
            ),
            (
                refused(s.f64s("h_b_nms", &[0.0, f64::NAN, 0.0])),
                "`h_b_nms[1]` = NaN",
            ),
            (
                refused(s.estimate([1.0, 0.0, f64::INFINITY, 0.0])),
                "`q_bn[2]` = inf",
            ),
        ];
        for ((code, m), field) in cases {
            assert_eq!(code, Code::Argument, "{m}");
            assert!(m.starts_with("stream `acs`: ") && m.contains(field), "{m}");
        }
        for _ in 0..MAX_FSW_EVENTS {
            s.event("gyro_fault").unwrap();
        }
        let (code, m) = refused(s.event("gyro_fault"));
        assert_eq!(code, Code::Argument);
        assert!(m.contains("holds 8 events already"), "{m}");
        // A value left out: nothing to send, and the sample stays begun.
        s.f64s("h_b_nms", &[0.0; 3]).unwrap();
        s.i64s("flags", &[1]).unwrap();
        let (code, m) = refused(s.encode());
        assert_eq!(code, Code::Usage);
        assert!(m.contains("lacks value `ok`"), "{m}");
        set_bools(&mut s, "ok", &[0]).unwrap();
        s.variance([1.0; 3]).unwrap();
        let (code, m) = refused(s.encode());
        assert_eq!(code, Code::Usage);
        assert!(m.contains("a variance without an estimate"), "{m}");
        s.estimate([1.0, 0.0, 0.0, 0.0]).unwrap();
        let m = decode_fsw(s.encode().unwrap()).unwrap();
        assert_eq!((m.header.seq, m.event_count), (0, 8));
        s.published();
        // Once published, the sample is gone, and its tick cannot be sent again.
        assert_eq!(refused(s.encode()).0, Code::Usage);
        let (code, m) = refused(s.begin_stamped(&stamp(1)));
        assert_eq!(code, Code::Usage);
        assert!(m.contains("at most one sample per tick per stream"), "{m}");
        s.begin_stamped(&stamp(2)).unwrap();
    }
}
