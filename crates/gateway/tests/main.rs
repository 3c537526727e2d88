//! The codecs against published definitions and examples: one executable, one module per
//! codec. Every expected value names its source or is derived in a comment.

mod ccsds;
mod checksum;
mod device;
mod framing;
mod nmea;
mod prng;
mod support;
