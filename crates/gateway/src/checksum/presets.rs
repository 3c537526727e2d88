//! Named CRCs, with the parameters of Greg Cook's "Catalogue of parametrised CRC algorithms"
//! (CRC RevEng, <https://reveng.sourceforge.io/crc-catalogue/all.htm>; the same entries are
//! mirrored in the `crc-catalog` crate's documentation). Each preset's published `check` (the
//! CRC of the ASCII string "123456789") and `residue` are in the tests
//! (`tests/checksum.rs`). Names are the catalogue's; its aliases are noted.

use super::CrcParams;

/// CRC-16/IBM-3740, alias CRC-16/CCITT-FALSE, CRC-16/AUTOSAR.
pub const CRC16_CCITT_FALSE: CrcParams = CrcParams {
    name: "CRC-16/IBM-3740",
    width_bits: 16,
    poly: 0x1021,
    init: 0xFFFF,
    refin: false,
    refout: false,
    xorout: 0,
};

/// CRC-16/KERMIT, alias CRC-16/CCITT, CRC-16/CCITT-TRUE, CRC-16/V-41-LSB.
pub const CRC16_KERMIT: CrcParams = CrcParams {
    name: "CRC-16/KERMIT",
    width_bits: 16,
    poly: 0x1021,
    init: 0,
    refin: true,
    refout: true,
    xorout: 0,
};

/// CRC-16/XMODEM, alias CRC-16/ACORN, CRC-16/LTE, CRC-16/V-41-MSB.
pub const CRC16_XMODEM: CrcParams = CrcParams {
    name: "CRC-16/XMODEM",
    width_bits: 16,
    poly: 0x1021,
    init: 0,
    refin: false,
    refout: false,
    xorout: 0,
};

/// CRC-16/IBM-SDLC, alias CRC-16/X-25, CRC-16/ISO-HDLC: the FCS-16 of HDLC and of RFC 1662
/// (PPP in HDLC-like framing, appendix C.2).
pub const CRC16_IBM_SDLC: CrcParams = CrcParams {
    name: "CRC-16/IBM-SDLC",
    width_bits: 16,
    poly: 0x1021,
    init: 0xFFFF,
    refin: true,
    refout: true,
    xorout: 0xFFFF,
};

/// CRC-32/ISO-HDLC, alias CRC-32, CRC-32/ADCCP, PKZIP: Ethernet's, zlib's, and the FCS-32 of
/// RFC 1662 (appendix C.3).
pub const CRC32: CrcParams = CrcParams {
    name: "CRC-32/ISO-HDLC",
    width_bits: 32,
    poly: 0x04C1_1DB7,
    init: 0xFFFF_FFFF,
    refin: true,
    refout: true,
    xorout: 0xFFFF_FFFF,
};

/// CRC-32/ISCSI, alias CRC-32C, CRC-32/CASTAGNOLI.
pub const CRC32C: CrcParams = CrcParams {
    name: "CRC-32/ISCSI",
    width_bits: 32,
    poly: 0x1EDC_6F41,
    init: 0xFFFF_FFFF,
    refin: true,
    refout: true,
    xorout: 0xFFFF_FFFF,
};

/// CRC-8/SMBUS, alias CRC-8: an 8-bit CRC.
pub const CRC8_SMBUS: CrcParams = CrcParams {
    name: "CRC-8/SMBUS",
    width_bits: 8,
    poly: 0x07,
    init: 0,
    refin: false,
    refout: false,
    xorout: 0,
};

/// CRC-5/USB: a width below one octet, reflected.
pub const CRC5_USB: CrcParams = CrcParams {
    name: "CRC-5/USB",
    width_bits: 5,
    poly: 0x05,
    init: 0x1F,
    refin: true,
    refout: true,
    xorout: 0x1F,
};

/// CRC-3/GSM: a width below one octet, not reflected.
pub const CRC3_GSM: CrcParams = CrcParams {
    name: "CRC-3/GSM",
    width_bits: 3,
    poly: 0x3,
    init: 0,
    refin: false,
    refout: false,
    xorout: 0x7,
};

/// Every preset, for look-up by name (a device description names its CRC).
pub const ALL: [CrcParams; 9] = [
    CRC16_CCITT_FALSE,
    CRC16_KERMIT,
    CRC16_XMODEM,
    CRC16_IBM_SDLC,
    CRC32,
    CRC32C,
    CRC8_SMBUS,
    CRC5_USB,
    CRC3_GSM,
];

/// The preset of this catalogue name or alias (`"CRC-16/CCITT-FALSE"`, `"CRC-32C"`, …),
/// case-insensitive.
pub fn by_name(name: &str) -> Option<CrcParams> {
    const ALIASES: [(&str, CrcParams); 8] = [
        ("CRC-16/CCITT-FALSE", CRC16_CCITT_FALSE),
        ("CRC-16/CCITT", CRC16_KERMIT),
        ("CRC-16/X-25", CRC16_IBM_SDLC),
        ("CRC-32", CRC32),
        ("CRC-32/ADCCP", CRC32),
        ("CRC-32C", CRC32C),
        ("CRC-32/CASTAGNOLI", CRC32C),
        ("CRC-8", CRC8_SMBUS),
    ];
    ALL.iter()
        .map(|p| (p.name, *p))
        .chain(ALIASES)
        .find(|(n, _)| n.eq_ignore_ascii_case(name))
        .map(|(_, p)| p)
}
