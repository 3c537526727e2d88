//! NMEA 0183 sentences written from typed inputs, byte for byte against published sentences.
//!
//! Sources of the expected sentences (each checksum re-derived: the XOR of the characters
//! between `$` and `*` gives the `*hh` printed):
//! - [DePriest]: Dale DePriest, "NMEA data", gpsinformation.org/dale/nmea.htm — the classic
//!   GGA `$GPGGA,123519,4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,*47` and RMC
//!   `$GPRMC,123519,A,4807.038,N,01131.000,E,022.4,084.4,230394,003.1,W*6A` (fix at 12:35:19
//!   UTC on 23 March 1994); the GGA is reproduced field by field in the University of Maine's
//!   NAAMES GPS notes (misclab.umeoce.maine.edu, NAV_MX5.txt) and Hohenheim's NMEA exercise;
//! - [NOAA]: NOAA PSL, PISTON 2019 cruise, R/V Sally Ride, raw GPS log
//!   downloads.psl.noaa.gov/psd3/cruises/PISTON_2019/Sally_Ride/flux/Raw/19259/gps01925920_raw.txt
//!   — the GGA, ZDA and RMC (NMEA 2.3, mode D) of 2019-09-16 20:00:00.00 UTC;
//! - [Otter]: a cyclist's receiver log, riverotter.xsrv.jp/bicycle/tours/2015/201505060659/05060823.nma
//!   — the GGA and RMC (mode A, no magnetic variation) of 2015-05-05 23:23:48.000 UTC;
//! - [ExRockets]: blog.exrockets.com/blog/wp-content/uploads/2015/08/GGA_2.txt — a GGA west of
//!   Greenwich with a negative geoid separation and DGPS fields `0000,0000`.

use flexdyn_gateway::nmea::{
    Dgps, FixQuality, Fixed, Gga, LocalZone, Mode, NmeaError, NmeaStyle, Rmc, Sentence, Talker, Zda,
};
use hifitime::Epoch;

/// Degrees of `degrees`° `minutes`′.
fn deg(degrees: f64, minutes: f64) -> f64 {
    degrees + minutes / 60.0
}

fn written(write: impl FnOnce(&mut String) -> Result<(), NmeaError>) -> String {
    let mut out = String::new();
    write(&mut out).unwrap();
    out
}

/// The sentence read back: envelope and field count valid.
fn read(sentence: &str) -> Sentence<'_> {
    let parsed = Sentence::parse(sentence).unwrap();
    parsed.expect_fields().unwrap();
    parsed
}

/// [DePriest]'s receiver: whole seconds, 3 decimals of a minute, RMC speed, course and
/// variation zero-padded to 3 integer digits.
fn depriest_style() -> NmeaStyle {
    NmeaStyle {
        time_decimals: 0,
        minute_decimals: 3,
        speed_knots: Fixed::new(3, 1),
        course_deg: Fixed::new(3, 1),
        magnetic_variation_deg: Fixed::new(3, 1),
        ..NmeaStyle::default()
    }
}

fn depriest_time() -> Epoch {
    Epoch::from_gregorian_utc_hms(1994, 3, 23, 12, 35, 19)
}

fn depriest_gga() -> Gga {
    Gga {
        time: depriest_time(),
        latitude_deg: deg(48.0, 7.038),
        longitude_deg: deg(11.0, 31.0),
        fix_quality: FixQuality::Gps,
        satellites: 8,
        hdop: 0.9,
        altitude_msl_m: 545.4,
        geoid_separation_m: 46.9,
        dgps: None,
    }
}

#[test]
fn gga_reproduces_the_classic_example() {
    let out = written(|out| depriest_gga().write(&depriest_style(), out));
    assert_eq!(
        out,
        "$GPGGA,123519,4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,*47\r\n"
    );
    let gga = read(&out);
    assert_eq!((gga.talker, gga.formatter), ("GP", "GGA"));
    assert!((gga.angle_deg(1).unwrap() - deg(48.0, 7.038)).abs() < 1e-12);
    assert!((gga.angle_deg(3).unwrap() - deg(11.0, 31.0)).abs() < 1e-12);
    assert_eq!(gga.number(8).unwrap(), 545.4);
}

#[test]
fn rmc_reproduces_the_classic_example() {
    let rmc = Rmc {
        time: depriest_time(),
        valid: true,
        latitude_deg: deg(48.0, 7.038),
        longitude_deg: deg(11.0, 31.0),
        speed_knots: 22.4,
        course_deg: 84.4,
        magnetic_variation_deg: Some(-3.1),
        mode: None,
    };
    let out = written(|out| rmc.write(&depriest_style(), out));
    assert_eq!(
        out,
        "$GPRMC,123519,A,4807.038,N,01131.000,E,022.4,084.4,230394,003.1,W*6A\r\n"
    );
    assert_eq!(read(&out).fields.len(), 11);
}

/// [NOAA]'s receiver: centiseconds, 8 decimals of a minute, speed and course with 2 decimals.
fn noaa_style() -> NmeaStyle {
    NmeaStyle {
        minute_decimals: 8,
        speed_knots: Fixed::new(1, 2),
        course_deg: Fixed::new(1, 2),
        ..NmeaStyle::default()
    }
}

fn noaa_time() -> Epoch {
    Epoch::from_gregorian_utc_hms(2019, 9, 16, 20, 0, 0)
}

#[test]
fn gga_with_differential_corrections_reproduces_a_survey_receiver() {
    let gga = Gga {
        time: noaa_time(),
        latitude_deg: deg(18.0, 13.382_740_46),
        longitude_deg: deg(126.0, 6.127_335),
        fix_quality: FixQuality::Differential,
        satellites: 7,
        hdop: 1.4,
        altitude_msl_m: 17.3,
        geoid_separation_m: 36.5,
        dgps: Some(Dgps {
            age_s: 5.0,
            station_id: 129,
        }),
    };
    let out = written(|out| gga.write(&noaa_style(), out));
    assert_eq!(
        out,
        "$GPGGA,200000.00,1813.38274046,N,12606.12733500,E,2,07,1.4,17.3,M,36.5,M,5.0,0129*7A\r\n"
    );
    read(&out);
}

#[test]
fn zda_reproduces_a_survey_receiver() {
    let zda = Zda {
        time: noaa_time(),
        local_zone: Some(LocalZone {
            hours: 0,
            minutes: 0,
        }),
    };
    let out = written(|out| zda.write(&noaa_style(), out));
    assert_eq!(out, "$GPZDA,200000.00,16,09,2019,00,00*60\r\n");
    read(&out);
}

/// UTC comes from the epoch in whatever time scale it is given: TAI − UTC = 37 s since
/// 2017-01-01 (IERS Bulletin C), so 20:00:37 TAI is [NOAA]'s 20:00:00 UTC.
#[test]
fn the_epoch_is_written_in_utc_whatever_its_time_scale() {
    let zda = Zda {
        time: Epoch::from_gregorian_tai_hms(2019, 9, 16, 20, 0, 37),
        local_zone: Some(LocalZone {
            hours: 0,
            minutes: 0,
        }),
    };
    let out = written(|out| zda.write(&noaa_style(), out));
    assert_eq!(out, "$GPZDA,200000.00,16,09,2019,00,00*60\r\n");
}

#[test]
fn rmc_with_mode_indicator_reproduces_a_survey_receiver() {
    let rmc = Rmc {
        time: noaa_time(),
        valid: true,
        latitude_deg: deg(18.0, 13.382_740_46),
        longitude_deg: deg(126.0, 6.127_335),
        speed_knots: 0.6,
        course_deg: 234.78,
        magnetic_variation_deg: Some(-3.0),
        mode: Some(Mode::Differential),
    };
    let out = written(|out| rmc.write(&noaa_style(), out));
    assert_eq!(
        out,
        "$GPRMC,200000.00,A,1813.38274046,N,12606.12733500,E,0.60,234.78,160919,3.0,W,D*28\r\n"
    );
    assert_eq!(read(&out).fields.len(), 12);
}

/// [Otter]'s receiver: milliseconds, 4 decimals of a minute, one-digit satellite count, HDOP
/// with 2 decimals, no magnetic variation.
fn otter_style() -> NmeaStyle {
    NmeaStyle {
        time_decimals: 3,
        satellites_digits: 1,
        hdop: Fixed::new(1, 2),
        speed_knots: Fixed::new(1, 2),
        course_deg: Fixed::new(1, 2),
        ..NmeaStyle::default()
    }
}

fn otter_time() -> Epoch {
    Epoch::from_gregorian_utc_hms(2015, 5, 5, 23, 23, 48)
}

#[test]
fn rmc_without_magnetic_variation_reproduces_a_handheld_receiver() {
    let rmc = Rmc {
        time: otter_time(),
        valid: true,
        latitude_deg: deg(36.0, 21.6309),
        longitude_deg: deg(136.0, 36.8487),
        speed_knots: 0.7,
        course_deg: 343.18,
        magnetic_variation_deg: None,
        mode: Some(Mode::Autonomous),
    };
    let out = written(|out| rmc.write(&otter_style(), out));
    assert_eq!(
        out,
        "$GPRMC,232348.000,A,3621.6309,N,13636.8487,E,0.70,343.18,050515,,,A*64\r\n"
    );
}

#[test]
fn gga_reproduces_a_handheld_receiver() {
    let gga = Gga {
        time: otter_time(),
        latitude_deg: deg(36.0, 21.6309),
        longitude_deg: deg(136.0, 36.8487),
        fix_quality: FixQuality::Gps,
        satellites: 6,
        hdop: 1.35,
        altitude_msl_m: 190.4,
        geoid_separation_m: 35.1,
        dgps: None,
    };
    let out = written(|out| gga.write(&otter_style(), out));
    assert_eq!(
        out,
        "$GPGGA,232348.000,3621.6309,N,13636.8487,E,1,6,1.35,190.4,M,35.1,M,,*52\r\n"
    );
}

/// West longitude, a negative geoid separation, and DGPS fields written `0000,0000` (an age
/// of 0 s with 4 integer digits, station 0).
#[test]
fn gga_west_with_negative_geoid_separation_reproduces_a_logger() {
    let style = NmeaStyle {
        dgps_age_s: Fixed::new(4, 0),
        ..otter_style()
    };
    let gga = Gga {
        time: Epoch::from_gregorian_utc_hms(2015, 8, 1, 18, 53, 12),
        latitude_deg: deg(45.0, 24.2243),
        longitude_deg: -deg(73.0, 27.6925),
        fix_quality: FixQuality::Differential,
        satellites: 8,
        hdop: 0.99,
        altitude_msl_m: 29.4,
        geoid_separation_m: -31.9,
        dgps: Some(Dgps {
            age_s: 0.0,
            station_id: 0,
        }),
    };
    let out = written(|out| gga.write(&style, out));
    assert_eq!(
        out,
        "$GPGGA,185312.000,4524.2243,N,07327.6925,W,2,8,0.99,29.4,M,-31.9,M,0000,0000*59\r\n"
    );
    assert!((read(&out).angle_deg(3).unwrap() + deg(73.0, 27.6925)).abs() < 1e-12);
}

/// 23:59:59.996 rounds to the next day's 00:00:00.00 with two decimals, in the time and the
/// date; 10° 59.99996′ rounds to 11° 00.0000′ with four, never to 10° 60.0000′.
#[test]
fn rounding_carries_into_seconds_days_and_degrees() {
    let rmc = Rmc {
        time: Epoch::from_gregorian_utc(2019, 12, 31, 23, 59, 59, 996_000_000),
        valid: false,
        latitude_deg: deg(10.0, 59.999_96),
        longitude_deg: -deg(0.0, 0.000_04),
        speed_knots: 0.0,
        course_deg: 0.0,
        magnetic_variation_deg: None,
        mode: Some(Mode::NotValid),
    };
    let out = written(|out| rmc.write(&NmeaStyle::default(), out));
    let rmc = read(&out);
    assert_eq!(rmc.field(0), "000000.00");
    assert_eq!(rmc.field(1), "V");
    assert_eq!((rmc.field(2), rmc.field(3)), ("1100.0000", "N"));
    // −0.00004′ rounds to zero: no "W" for a longitude written as zero.
    assert_eq!((rmc.field(4), rmc.field(5)), ("00000.0000", "E"));
    assert_eq!(rmc.field(8), "010120");
    // And 23:59:59.994 stays in the old day.
    let zda = Zda {
        time: Epoch::from_gregorian_utc(2019, 12, 31, 23, 59, 59, 994_000_000),
        local_zone: None,
    };
    let out = written(|out| zda.write(&NmeaStyle::default(), out));
    assert_eq!(read(&out).fields, ["235959.99", "31", "12", "2019", "", ""]);
}

#[test]
fn the_talker_id_and_the_local_zone_are_written_as_given() {
    let style = NmeaStyle {
        talker: Talker::new("GN").unwrap(),
        ..NmeaStyle::default()
    };
    let zda = Zda {
        time: noaa_time(),
        local_zone: Some(LocalZone {
            hours: -5,
            minutes: 30,
        }),
    };
    let out = written(|out| zda.write(&style, out));
    let zda = read(&out);
    assert_eq!(zda.talker, "GN");
    assert_eq!(&zda.fields[4..], ["-05", "30"]);
    assert_eq!(
        Talker::new("gp").unwrap_err(),
        NmeaError::Talker("gp".into())
    );
    assert!(Talker::new("GPS").is_err());
}

#[test]
fn inputs_a_sentence_cannot_hold_are_refused_and_nothing_is_written() {
    let style = NmeaStyle::default();
    let mut out = String::new();
    let nan = Gga {
        latitude_deg: f64::NAN,
        ..depriest_gga()
    };
    assert!(matches!(
        nan.write(&style, &mut out),
        Err(NmeaError::NotFinite {
            field: "latitude_deg",
            ..
        })
    ));
    let north_of_pole = Gga {
        latitude_deg: 90.5,
        ..depriest_gga()
    };
    let err = north_of_pole.write(&style, &mut out).unwrap_err();
    assert_eq!(err.to_string(), "latitude_deg = 90.5 is outside -90..=90");
    let negative_hdop = Gga {
        hdop: -1.0,
        ..depriest_gga()
    };
    assert!(matches!(
        negative_hdop.write(&style, &mut out),
        Err(NmeaError::OutOfRange { field: "hdop", .. })
    ));
    let station = Gga {
        dgps: Some(Dgps {
            age_s: 1.0,
            station_id: 1024,
        }),
        ..depriest_gga()
    };
    assert!(station.write(&style, &mut out).is_err());
    let zone = Zda {
        time: noaa_time(),
        local_zone: Some(LocalZone {
            hours: 14,
            minutes: 0,
        }),
    };
    assert!(matches!(
        zone.write(&style, &mut out),
        Err(NmeaError::OutOfRange {
            field: "local_zone.hours",
            ..
        })
    ));
    let too_fine = NmeaStyle {
        minute_decimals: 10,
        ..style
    };
    let err = depriest_gga().write(&too_fine, &mut out).unwrap_err();
    assert_eq!(
        err,
        NmeaError::Decimals {
            field: "minute_decimals",
            decimals: 10,
            max: 9
        }
    );
    assert!(out.is_empty());
}

#[test]
fn the_reader_refuses_damaged_sentences_with_the_reason() {
    let good = "$GPGGA,123519,4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,*47";
    assert!(Sentence::parse(good).is_ok());
    let altered = good.replace("545.4", "545.5");
    let err = Sentence::parse(&altered).unwrap_err();
    // '4' ^ '5' = 0x01: the characters now XOR to 0x46.
    assert_eq!(
        err,
        NmeaError::ChecksumMismatch {
            stated: 0x47,
            computed: 0x46
        }
    );
    assert_eq!(
        err.to_string(),
        "checksum mismatch: the sentence says 47, its characters give 46"
    );
    assert!(matches!(
        Sentence::parse(&good[1..]),
        Err(NmeaError::NoDollar(_))
    ));
    assert!(matches!(
        Sentence::parse(&good[..good.len() - 3]),
        Err(NmeaError::NoChecksum(_))
    ));
    assert!(matches!(
        Sentence::parse(&good.replace("*47", "*4G")),
        Err(NmeaError::ChecksumDigits(_))
    ));
    assert!(matches!(
        Sentence::parse(&good.replace("*47", "*+7")),
        Err(NmeaError::ChecksumDigits(_))
    ));
    assert!(matches!(
        Sentence::parse("$GPGGA,1\u{7}*00"),
        Err(NmeaError::NotPrintable { position: 8 })
    ));
    // One field fewer (the last comma dropped), checksum made right again: the field count
    // catches it. ',' = 0x2C, so the XOR becomes 0x47 ^ 0x2C = 0x6B.
    let short = Sentence::parse("$GPGGA,123519,4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,*6B")
        .unwrap();
    let err = short.expect_fields().unwrap_err();
    assert_eq!(err.to_string(), "GGA sentence has 13 fields, expected 14");
}
