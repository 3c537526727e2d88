//! Checksums against published values.
//!
//! CRC check and residue values: Greg Cook, "Catalogue of parametrised CRC algorithms" (CRC
//! RevEng, https://reveng.sourceforge.io/crc-catalogue/all.htm; the same entries are in the
//! `crc-catalog` crate's documentation). `check` is the CRC of the nine ASCII octets
//! "123456789"; `residue` is the register, without `xorout`, after an error-free codeword.
//! RFC 1662 appendix C gives the same two residues for its FCS-16 (0xf0b8, "PPPGOODFCS16")
//! and FCS-32 (0xdebb20e3, "PPPGOODFCS32").
//!
//! Fletcher values: Wikipedia, "Fletcher's checksum", section "Test vectors" (Fletcher-16
//! "abcde" → 51440 = 0xC8F0, "abcdef" → 8279 = 0x2057, "abcdefgh" → 1575 = 0x0627;
//! Fletcher-32 over little-endian 16-bit blocks "abcde" → 4031760169 = 0xF04FC729, "abcdef" →
//! 1448095018 = 0x56502D2A, "abcdefgh" → 3957429649 = 0xEBE19591); the first two Fletcher-16
//! values are also quoted by the Nim gist jackhftang/41841838 citing that section, and
//! Fletcher-32 "abcdef" = 0x56502d2a by the Stack Overflow question "Fletcher 32-bit checksum
//! test vectors".

use flexdyn_gateway::checksum::fletcher::{fletcher16, fletcher32};
use flexdyn_gateway::checksum::presets::{self, *};
use flexdyn_gateway::checksum::sums::{sum8, xor8};
use flexdyn_gateway::checksum::{Checksum, ChecksumError, Crc, CrcParams};
use flexdyn_gateway::ByteOrder;

const CHECK_INPUT: &[u8] = b"123456789";

/// (preset, published check, published residue).
const CATALOGUE: [(CrcParams, u32, u32); 9] = [
    (CRC16_CCITT_FALSE, 0x29B1, 0x0000),
    (CRC16_KERMIT, 0x2189, 0x0000),
    (CRC16_XMODEM, 0x31C3, 0x0000),
    (CRC16_IBM_SDLC, 0x906E, 0xF0B8),
    (CRC32, 0xCBF4_3926, 0xDEBB_20E3),
    (CRC32C, 0xE306_9283, 0xB798_B438),
    (CRC8_SMBUS, 0xF4, 0x00),
    (CRC5_USB, 0x19, 0x06),
    (CRC3_GSM, 0x4, 0x2),
];

#[test]
fn every_preset_gives_its_published_check_value() {
    for (params, check, _) in CATALOGUE {
        let crc = Crc::new(params).unwrap();
        assert_eq!(crc.checksum(CHECK_INPUT), check, "{}", params.name);
    }
}

/// The codeword is the message then its CRC, least significant octet first for a reflected
/// CRC, most significant first otherwise (whole-octet widths only: CRC-5 and CRC-3 have no
/// octet codeword).
#[test]
fn every_whole_octet_preset_gives_its_published_residue() {
    for (params, check, residue) in CATALOGUE.iter().filter(|(p, _, _)| p.width_bits % 8 == 0) {
        let crc = Crc::new(*params).unwrap();
        let order = if params.refout {
            ByteOrder::LittleEndian
        } else {
            ByteOrder::BigEndian
        };
        let mut codeword = CHECK_INPUT.to_vec();
        order.write_uint(u64::from(*check), crc.width_bytes(), &mut codeword);
        assert_eq!(crc.residue(&codeword), *residue, "{}", params.name);
        // And a corrupted codeword does not give it.
        codeword[3] ^= 0x10;
        assert_ne!(crc.residue(&codeword), *residue, "{}", params.name);
    }
}

#[test]
fn updating_in_pieces_equals_one_pass() {
    for (params, check, _) in CATALOGUE {
        let crc = Crc::new(params).unwrap();
        let (a, b) = CHECK_INPUT.split_at(4);
        let register = crc.update(crc.update(crc.start(), a), b);
        assert_eq!(crc.finish(register), check, "{}", params.name);
    }
}

#[test]
fn presets_are_found_by_catalogue_name_and_alias() {
    assert_eq!(
        presets::by_name("crc-16/ccitt-false"),
        Some(CRC16_CCITT_FALSE)
    );
    assert_eq!(presets::by_name("CRC-16/IBM-3740"), Some(CRC16_CCITT_FALSE));
    assert_eq!(presets::by_name("CRC-32C"), Some(CRC32C));
    assert_eq!(presets::by_name("CRC-32"), Some(CRC32));
    assert_eq!(presets::by_name("CRC-16/X-25"), Some(CRC16_IBM_SDLC));
    assert_eq!(presets::by_name("CRC-7/MMC"), None);
}

#[test]
fn impossible_parameters_are_refused_with_what_is_wrong() {
    let base = CRC16_XMODEM;
    let err = Crc::new(CrcParams {
        width_bits: 0,
        ..base
    })
    .unwrap_err();
    assert_eq!(
        err,
        ChecksumError::Width {
            name: base.name,
            width_bits: 0
        }
    );
    assert!(Crc::new(CrcParams {
        width_bits: 33,
        ..base
    })
    .is_err());
    let err = Crc::new(CrcParams {
        poly: 0x1_1021,
        ..base
    })
    .unwrap_err();
    assert_eq!(
        err.to_string(),
        "CRC `CRC-16/XMODEM`: poly = 0x11021 does not fit in 16 bits"
    );
    let err = Crc::new(CrcParams {
        init: 0x1_0000,
        ..base
    })
    .unwrap_err();
    assert!(err.to_string().contains("init"), "{err}");
    let err = Crc::new(CrcParams {
        poly: 0x1020,
        ..base
    })
    .unwrap_err();
    assert_eq!(
        err,
        ChecksumError::EvenPoly {
            name: base.name,
            poly: 0x1020
        }
    );
}

#[test]
fn fletcher16_gives_the_published_test_vectors() {
    assert_eq!(fletcher16(b"abcde"), 0xC8F0);
    assert_eq!(fletcher16(b"abcdef"), 0x2057);
    assert_eq!(fletcher16(b"abcdefgh"), 0x0627);
}

#[test]
fn fletcher32_gives_the_published_test_vectors() {
    assert_eq!(fletcher32(b"abcde", ByteOrder::LittleEndian), 0xF04F_C729);
    assert_eq!(fletcher32(b"abcdef", ByteOrder::LittleEndian), 0x5650_2D2A);
    assert_eq!(
        fletcher32(b"abcdefgh", ByteOrder::LittleEndian),
        0xEBE1_9591
    );
}

/// "ab" is one block: 0x6162 read big-endian, 0x6261 little-endian; a = b = the block, so the
/// checksum is the block twice.
#[test]
fn fletcher32_reads_blocks_in_the_order_given() {
    assert_eq!(fletcher32(b"ab", ByteOrder::BigEndian), 0x6162_6162);
    assert_eq!(fletcher32(b"ab", ByteOrder::LittleEndian), 0x6261_6261);
    // An odd last octet is padded with zero: "a" is 0x6100 big-endian, 0x0061 little-endian.
    assert_eq!(fletcher32(b"a", ByteOrder::BigEndian), 0x6100_6100);
    assert_eq!(fletcher32(b"a", ByteOrder::LittleEndian), 0x0061_0061);
}

/// "123456789" is 0x31..=0x39. XOR: 0x31^0x32 = 0x03, ^0x33 = 0x30, ^0x34 = 0x04, ^0x35 = 0x31,
/// ^0x36 = 0x07, ^0x37 = 0x30, ^0x38 = 0x08, ^0x39 = 0x31. Sum: 9·0x30 + (1+…+9) = 432 + 45 =
/// 477 = 0x1DD, modulo 256 0xDD.
#[test]
fn xor8_and_sum8_of_the_check_string() {
    assert_eq!(xor8(CHECK_INPUT), 0x31);
    assert_eq!(sum8(CHECK_INPUT), 0xDD);
    assert_eq!(xor8(&[]), 0);
    assert_eq!(sum8(&[0xFF, 0x02]), 0x01);
}

#[test]
fn a_checksum_chosen_at_run_time_has_its_width_and_value() {
    let kinds = [
        (
            Checksum::Crc(Box::new(Crc::new(CRC32).unwrap())),
            4,
            0xCBF4_3926,
        ),
        (
            Checksum::Crc(Box::new(Crc::new(CRC5_USB).unwrap())),
            1,
            0x19,
        ),
        (Checksum::Xor8, 1, 0x31),
        (Checksum::Sum8, 1, 0xDD),
        (Checksum::Fletcher16, 2, u32::from(fletcher16(CHECK_INPUT))),
        (
            Checksum::Fletcher32(ByteOrder::BigEndian),
            4,
            fletcher32(CHECK_INPUT, ByteOrder::BigEndian),
        ),
    ];
    for (kind, width, value) in kinds {
        assert_eq!(kind.width_bytes(), width, "{kind:?}");
        assert_eq!(kind.compute(CHECK_INPUT), value, "{kind:?}");
    }
}
