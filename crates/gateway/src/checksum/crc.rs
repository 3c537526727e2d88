//! A CRC in the Rocksoft™ parametric model (R. N. Williams, "A painless guide to CRC error
//! detection algorithms", 1993, §15), the model of Greg Cook's CRC RevEng catalogue
//! (<https://reveng.sourceforge.io/crc-catalogue/all.htm>): `width`, `poly` (normal form,
//! x^width implied), `init`, `refin`, `refout`, `xorout`.
//!
//! Table-driven, one byte per step (Williams §10 for the direct form, §11 for the reflected
//! form). Any width from 1 to 32 bits:
//! - not reflected: the register is kept left-aligned in 32 bits (the top `width` bits), so a
//!   byte enters at bits 31..24 whatever the width, and the result is shifted down at the end;
//! - reflected: the register is kept reflected in the low `width` bits, with the reflected
//!   polynomial, and a byte enters at bits 7..0.

use super::ChecksumError;

/// The parameters of a CRC, as the RevEng catalogue lists them.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CrcParams {
    /// The catalogue name, for messages.
    pub name: &'static str,
    /// Width in bits (1 to 32).
    pub width_bits: u8,
    /// Generator polynomial in normal (MSB-first) form, without the x^width term.
    pub poly: u32,
    /// Register value before the first byte (unreflected).
    pub init: u32,
    /// Each input byte is reflected (least significant bit first).
    pub refin: bool,
    /// The final register is reflected before `xorout`.
    pub refout: bool,
    /// XORed into the result.
    pub xorout: u32,
}

/// A CRC ready to compute: its parameters and its 256-entry table.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Crc {
    params: CrcParams,
    table: [u32; 256],
}

/// The low `width` bits set.
fn mask(width_bits: u8) -> u32 {
    if width_bits >= 32 {
        u32::MAX
    } else {
        (1u32 << width_bits) - 1
    }
}

/// The low `width` bits of `value` in reverse order.
fn reflect(value: u32, width_bits: u8) -> u32 {
    value.reverse_bits() >> (32 - u32::from(width_bits))
}

impl Crc {
    /// Checks the parameters and builds the table.
    pub fn new(params: CrcParams) -> Result<Self, ChecksumError> {
        let CrcParams {
            name,
            width_bits,
            poly,
            init,
            xorout,
            ..
        } = params;
        if !(1..=32).contains(&width_bits) {
            return Err(ChecksumError::Width { name, width_bits });
        }
        for (parameter, value) in [("poly", poly), ("init", init), ("xorout", xorout)] {
            if value & !mask(width_bits) != 0 {
                return Err(ChecksumError::ParameterTooWide {
                    name,
                    parameter,
                    value,
                    width_bits,
                });
            }
        }
        if poly & 1 == 0 {
            return Err(ChecksumError::EvenPoly { name, poly });
        }
        let mut table = [0u32; 256];
        for (byte, entry) in table.iter_mut().enumerate() {
            *entry = if params.refin {
                let poly_reflected = reflect(poly, width_bits);
                (0..8).fold(byte as u32, |r, _| {
                    if r & 1 != 0 {
                        (r >> 1) ^ poly_reflected
                    } else {
                        r >> 1
                    }
                })
            } else {
                let poly_aligned = poly << (32 - u32::from(width_bits));
                (0..8).fold((byte as u32) << 24, |r, _| {
                    if r & 0x8000_0000 != 0 {
                        (r << 1) ^ poly_aligned
                    } else {
                        r << 1
                    }
                })
            };
        }
        Ok(Self { params, table })
    }

    /// The parameters.
    pub fn params(&self) -> &CrcParams {
        &self.params
    }

    /// Octets the CRC takes on the wire: ⌈width / 8⌉.
    pub fn width_bytes(&self) -> usize {
        usize::from(self.params.width_bits).div_ceil(8)
    }

    /// The register before the first byte, in the internal orientation.
    pub fn start(&self) -> u32 {
        let CrcParams {
            width_bits,
            init,
            refin,
            ..
        } = self.params;
        if refin {
            reflect(init, width_bits)
        } else {
            init << (32 - u32::from(width_bits))
        }
    }

    /// The register after `data`, from `register` (of [`Crc::start`] or a previous update).
    pub fn update(&self, register: u32, data: &[u8]) -> u32 {
        if self.params.refin {
            data.iter().fold(register, |r, &b| {
                (r >> 8) ^ self.table[((r ^ u32::from(b)) & 0xFF) as usize]
            })
        } else {
            data.iter().fold(register, |r, &b| {
                (r << 8) ^ self.table[(((r >> 24) ^ u32::from(b)) & 0xFF) as usize]
            })
        }
    }

    /// The register in the output orientation (reflected if `refout`), before `xorout`.
    fn unxored(&self, register: u32) -> u32 {
        let CrcParams {
            width_bits,
            refin,
            refout,
            ..
        } = self.params;
        let value = if refin {
            register
        } else {
            register >> (32 - u32::from(width_bits))
        };
        if refin == refout {
            value
        } else {
            reflect(value, width_bits)
        }
    }

    /// The CRC from the register after the last byte.
    pub fn finish(&self, register: u32) -> u32 {
        self.unxored(register) ^ self.params.xorout
    }

    /// The CRC of `data`.
    pub fn checksum(&self, data: &[u8]) -> u32 {
        self.finish(self.update(self.start(), data))
    }

    /// The register after a whole codeword (message then its CRC), in the output orientation
    /// and without `xorout`: the catalogue's `residue`, a constant for every error-free
    /// codeword. The CRC is appended least significant octet first when `refout`, most
    /// significant first otherwise (the order that keeps the polynomial's bit order on a
    /// bit-serial line); widths that are not whole octets have no such byte codeword.
    pub fn residue(&self, codeword: &[u8]) -> u32 {
        self.unxored(self.update(self.start(), codeword))
    }
}
