//! Framings: published examples, hand-derived frames, random round trips, chunking, and
//! malformed input counted by reason.

use flexdyn_gateway::checksum::presets::{CRC16_CCITT_FALSE, CRC16_IBM_SDLC, CRC32};
use flexdyn_gateway::checksum::{Checksum, Crc};
use flexdyn_gateway::framing::cobs::{self, CobsDecoder};
use flexdyn_gateway::framing::hdlc::{HdlcDecoder, HdlcFraming};
use flexdyn_gateway::framing::length::{
    LengthCounts, LengthDecoder, LengthField, LengthFraming, LengthFramingConfig,
};
use flexdyn_gateway::framing::lines::{self, LineDecoder, LineEnding};
use flexdyn_gateway::framing::slip::{self, SlipDecoder};
use flexdyn_gateway::framing::{DecodeCounters, FrameCheck, FramingError, StreamDecoder};
use flexdyn_gateway::ByteOrder;

use crate::prng::SplitMix64;

/// Frames and counters after feeding `stream` in the given chunk lengths (cycled).
fn decode_in_chunks(
    decoder: &mut dyn StreamDecoder,
    stream: &[u8],
    chunks: &[usize],
) -> (Vec<Vec<u8>>, DecodeCounters) {
    let mut frames = Vec::new();
    let mut rest = stream;
    for &len in chunks.iter().cycle() {
        if rest.is_empty() {
            break;
        }
        let (chunk, tail) = rest.split_at(len.clamp(1, rest.len()));
        decoder.feed(chunk, &mut |frame| frames.push(frame.to_vec()));
        rest = tail;
    }
    (frames, *decoder.counters())
}

/// Whole, byte by byte, and in uneven chunks: the same frames and counters.
fn decode_every_way(
    make: &dyn Fn() -> Box<dyn StreamDecoder>,
    stream: &[u8],
) -> (Vec<Vec<u8>>, DecodeCounters) {
    let whole = decode_in_chunks(&mut *make(), stream, &[stream.len()]);
    let bytewise = decode_in_chunks(&mut *make(), stream, &[1]);
    let uneven = decode_in_chunks(&mut *make(), stream, &[3, 1, 7, 2, 64, 5]);
    assert_eq!(
        bytewise, whole,
        "byte-at-a-time feeding differs from whole-buffer feeding"
    );
    assert_eq!(
        uneven, whole,
        "uneven chunks differ from whole-buffer feeding"
    );
    whole
}

/// The counters of a clean stream: `frames` delivered, nothing rejected.
fn clean(frames: u64) -> DecodeCounters {
    DecodeCounters {
        frames,
        ..Default::default()
    }
}

fn crc(params: flexdyn_gateway::checksum::CrcParams) -> Checksum {
    Checksum::Crc(Box::new(Crc::new(params).unwrap()))
}

/// Random payloads of 1 to `max_len` octets (none empty: the delimiter framings skip empty
/// frames by design).
fn random_payloads(rng: &mut SplitMix64, count: usize, max_len: usize) -> Vec<Vec<u8>> {
    (0..count)
        .map(|_| {
            let len = 1 + rng.below(max_len);
            rng.bytes(len)
        })
        .collect()
}

// --- SLIP (RFC 1055) ---

/// RFC 1055: END = 0xC0, ESC = 0xDB, END in data → ESC ESC_END (0xDB 0xDC), ESC → ESC ESC_ESC
/// (0xDB 0xDD); the encoder sends END before and after the packet.
#[test]
fn slip_escapes_end_and_esc_as_rfc_1055_specifies() {
    let mut out = Vec::new();
    slip::encode(&[0x01, 0xC0, 0x02, 0xDB, 0x03], &mut out);
    assert_eq!(out, [0xC0, 0x01, 0xDB, 0xDC, 0x02, 0xDB, 0xDD, 0x03, 0xC0]);
    let (frames, counters) = decode_every_way(&|| Box::new(SlipDecoder::new(16)), &out);
    assert_eq!(frames, [vec![0x01, 0xC0, 0x02, 0xDB, 0x03]]);
    assert_eq!(counters, clean(1));
}

/// ESC then 0x05 (neither ESC_END nor ESC_ESC): that frame is rejected, the next delivered.
#[test]
fn slip_counts_a_bad_escape_and_keeps_the_next_frame() {
    let stream = [
        0xC0, 0x01, 0xDB, 0x05, 0x02, 0xC0, 0x07, 0xC0, 0x08, 0xDB, 0xC0,
    ];
    let (frames, counters) = decode_every_way(&|| Box::new(SlipDecoder::new(16)), &stream);
    assert_eq!(frames, [vec![0x07]]);
    // The first frame's bad escape and the third's ESC END.
    assert_eq!(
        counters,
        DecodeCounters {
            bad_escape: 2,
            ..clean(1)
        }
    );
}

#[test]
fn slip_drops_an_oversize_frame_whole_and_counts_it_once() {
    let mut stream = Vec::new();
    slip::encode(&[0x55; 9], &mut stream);
    slip::encode(&[0x66; 8], &mut stream);
    let (frames, counters) = decode_every_way(&|| Box::new(SlipDecoder::new(8)), &stream);
    assert_eq!(frames, [vec![0x66; 8]]);
    assert_eq!(
        counters,
        DecodeCounters {
            oversize: 1,
            ..clean(1)
        }
    );
}

// --- COBS (Cheshire & Baker 1999) ---

/// The examples of Wikipedia's "Consistent Overhead Byte Stuffing" article (section
/// "Encoding examples"), each checked against the paper's rule (§3): a code octet is the
/// distance to the next zero, 0xFF a run of 254 non-zero octets with no zero after it.
#[test]
fn cobs_encodes_the_published_examples() {
    let run = |from: u8, to: u8| (from..=to).collect::<Vec<u8>>();
    let cat = |parts: &[&[u8]]| parts.concat();
    let examples: Vec<(Vec<u8>, Vec<u8>)> = vec![
        (vec![0x00], vec![0x01, 0x01, 0x00]),
        (vec![0x00, 0x00], vec![0x01, 0x01, 0x01, 0x00]),
        (vec![0x00, 0x11, 0x00], vec![0x01, 0x02, 0x11, 0x01, 0x00]),
        (
            vec![0x11, 0x22, 0x00, 0x33],
            vec![0x03, 0x11, 0x22, 0x02, 0x33, 0x00],
        ),
        (
            vec![0x11, 0x22, 0x33, 0x44],
            vec![0x05, 0x11, 0x22, 0x33, 0x44, 0x00],
        ),
        (
            vec![0x11, 0x00, 0x00, 0x00],
            vec![0x02, 0x11, 0x01, 0x01, 0x01, 0x00],
        ),
        // 01..FE (254 octets): one full block, nothing after it.
        (run(0x01, 0xFE), cat(&[&[0xFF], &run(0x01, 0xFE), &[0x00]])),
        // 00..FE (255 octets).
        (
            run(0x00, 0xFE),
            cat(&[&[0x01, 0xFF], &run(0x01, 0xFE), &[0x00]]),
        ),
        // 01..FF (255 octets).
        (
            run(0x01, 0xFF),
            cat(&[&[0xFF], &run(0x01, 0xFE), &[0x02, 0xFF, 0x00]]),
        ),
        // 02..FF then 00 (255 octets).
        (
            cat(&[&run(0x02, 0xFF), &[0x00]]),
            cat(&[&[0xFF], &run(0x02, 0xFF), &[0x01, 0x01, 0x00]]),
        ),
        // 03..FF then 00 01 (255 octets).
        (
            cat(&[&run(0x03, 0xFF), &[0x00, 0x01]]),
            cat(&[&[0xFE], &run(0x03, 0xFF), &[0x02, 0x01, 0x00]]),
        ),
    ];
    for (payload, encoded) in &examples {
        let mut out = Vec::new();
        cobs::encode(payload, &mut out);
        assert_eq!(&out, encoded, "payload {payload:02X?}");
        let (frames, counters) = decode_every_way(&|| Box::new(CobsDecoder::new(300)), encoded);
        assert_eq!(frames, std::slice::from_ref(payload));
        assert_eq!(counters.frames, 1);
        assert!(out.len() - 1 <= cobs::max_encoded_len(payload.len()));
    }
}

/// 0x05 announces four data octets, one follows before the delimiter.
#[test]
fn cobs_counts_a_block_that_runs_past_the_frame() {
    let mut stream = vec![0x05, 0x11, 0x00];
    cobs::encode(&[0x42], &mut stream);
    let (frames, counters) = decode_every_way(&|| Box::new(CobsDecoder::new(8)), &stream);
    assert_eq!(frames, [vec![0x42]]);
    assert_eq!(
        counters,
        DecodeCounters {
            bad_encoding: 1,
            ..clean(1)
        }
    );
}

// --- HDLC-like framing (RFC 1662) ---

fn fcs16() -> FrameCheck {
    FrameCheck {
        checksum: crc(CRC16_IBM_SDLC),
        order: ByteOrder::LittleEndian,
    }
}

/// RFC 1662 §4.2: 0x7E → 0x7D 0x5E, 0x7D → 0x7D 0x5D, and with the default ACCM (all 32
/// control characters) 0x01 → 0x7D 0x21; 0x41 is sent as is.
#[test]
fn hdlc_stuffs_flag_escape_and_mapped_control_octets() {
    let framing = HdlcFraming {
        fcs: None,
        accm: 0xFFFF_FFFF,
    };
    let mut out = Vec::new();
    framing.encode(&[0x7E, 0x7D, 0x01, 0x41], &mut out);
    assert_eq!(out, [0x7E, 0x7D, 0x5E, 0x7D, 0x5D, 0x7D, 0x21, 0x41, 0x7E]);
    let mut unmapped = Vec::new();
    HdlcFraming { fcs: None, accm: 0 }.encode(&[0x01], &mut unmapped);
    assert_eq!(unmapped, [0x7E, 0x01, 0x7E]);
    let (frames, _) = decode_every_way(&|| Box::new(HdlcDecoder::new(&framing, 16)), &out);
    assert_eq!(frames, [vec![0x7E, 0x7D, 0x01, 0x41]]);
}

/// The FCS-16 is sent least significant octet first (RFC 1662 §C.2), so the unstuffed frame
/// content + FCS leaves the CRC register at the "good FCS" 0xF0B8 (RFC 1662 §C.2, the
/// catalogue's residue).
#[test]
fn hdlc_fcs16_frame_gives_the_rfc_1662_good_fcs() {
    let framing = HdlcFraming {
        fcs: Some(fcs16()),
        accm: 0,
    };
    let content = *b"\xFF\x03\xC0\x21hello";
    let mut out = Vec::new();
    framing.encode(&content, &mut out);
    let unstuffed: Vec<u8> = {
        let mut v = Vec::new();
        let mut esc = false;
        for &b in &out[1..out.len() - 1] {
            if esc {
                v.push(b ^ 0x20);
                esc = false;
            } else if b == 0x7D {
                esc = true;
            } else {
                v.push(b);
            }
        }
        v
    };
    assert_eq!(
        Crc::new(CRC16_IBM_SDLC).unwrap().residue(&unstuffed),
        0xF0B8
    );
    let (frames, counters) = decode_every_way(&|| Box::new(HdlcDecoder::new(&framing, 32)), &out);
    assert_eq!(frames, [content.to_vec()]);
    assert_eq!(counters, clean(1));
}

/// Garbage before the first flag, a frame with a flipped octet (bad FCS), an aborted frame
/// (0x7D 0x7E), a frame shorter than its FCS, then a good frame.
#[test]
fn hdlc_counts_garbage_bad_fcs_abort_and_runt() {
    let framing = HdlcFraming {
        fcs: Some(fcs16()),
        accm: 0,
    };
    let mut stream = vec![0x11, 0x22, 0x33];
    let mut bad = Vec::new();
    framing.encode(b"abc", &mut bad);
    bad[2] ^= 0x01;
    stream.extend_from_slice(&bad);
    stream.extend_from_slice(&[0x41, 0x42, 0x7D, 0x7E]);
    stream.extend_from_slice(&[0x41, 0x7E]);
    framing.encode(b"good", &mut stream);
    let (frames, counters) =
        decode_every_way(&|| Box::new(HdlcDecoder::new(&framing, 32)), &stream);
    assert_eq!(frames, [b"good".to_vec()]);
    let expected = DecodeCounters {
        garbage_bytes: 3,
        bad_checksum: 1,
        aborted: 1,
        bad_length: 1,
        ..clean(1)
    };
    assert_eq!(counters, expected);
}

// --- Lines ---

#[test]
fn lines_end_at_lf_with_or_without_cr_and_skip_empty_ones() {
    let stream = b"abc\r\ndef\n\r\n\nxyz";
    let (frames, counters) = decode_every_way(&|| Box::new(LineDecoder::new(8)), stream);
    assert_eq!(frames, [b"abc".to_vec(), b"def".to_vec()]);
    assert_eq!(counters.frames, 2);
    let mut decoder = LineDecoder::new(8);
    decoder.feed(stream, &mut |_| {});
    assert_eq!(decoder.pending_bytes(), 3);
}

#[test]
fn lines_drop_an_oversize_line_and_count_it_once() {
    let stream = b"123456789\r\n12345678\r\n1234567890123\n";
    let (frames, counters) = decode_every_way(&|| Box::new(LineDecoder::new(8)), stream);
    assert_eq!(frames, [b"12345678".to_vec()]);
    assert_eq!(
        counters,
        DecodeCounters {
            oversize: 2,
            ..clean(1)
        }
    );
}

#[test]
fn a_line_holding_a_terminator_is_refused() {
    let mut out = Vec::new();
    let err = lines::encode(b"ab\ncd", LineEnding::CrLf, &mut out).unwrap_err();
    assert_eq!(
        err,
        FramingError::TerminatorInLine {
            what: "LF",
            position: 2
        }
    );
    assert_eq!(
        err.to_string(),
        "line contains a LF at octet 2: it would end the line early"
    );
    assert!(out.is_empty());
    lines::encode(b"ab", LineEnding::CrLf, &mut out).unwrap();
    lines::encode(b"cd", LineEnding::Lf, &mut out).unwrap();
    assert_eq!(out, b"ab\r\ncd\n");
}

// --- Sync and length ---

/// Sync 0xAA 0x55, one header octet (message id), a 2-octet little-endian length of the
/// payload, the payload, CRC-16/CCITT-FALSE big-endian over the payload only.
fn vendor_framing(max_frame_bytes: usize) -> LengthFraming {
    vendor_framing_checked_from(5, max_frame_bytes)
}

/// [`vendor_framing`] with the CRC covering the frame from `check_from_bytes`.
fn vendor_framing_checked_from(check_from_bytes: usize, max_frame_bytes: usize) -> LengthFraming {
    LengthFraming::new(LengthFramingConfig {
        sync: vec![0xAA, 0x55],
        length: LengthField {
            offset_bytes: 3,
            width_bytes: 2,
            order: ByteOrder::LittleEndian,
            counts: LengthCounts::Payload,
            adjust: 0,
        },
        check: Some(FrameCheck {
            checksum: crc(CRC16_CCITT_FALSE),
            order: ByteOrder::BigEndian,
        }),
        check_from_bytes,
        max_frame_bytes,
    })
    .unwrap()
}

/// AA 55 | id 07 | length 9 = 09 00 (little-endian) | "123456789" | CRC-16/CCITT-FALSE of
/// "123456789" = 0x29B1 (the catalogue's check value), big-endian 29 B1.
#[test]
fn a_sync_length_frame_is_laid_out_as_configured() {
    let framing = vendor_framing(64);
    let mut out = Vec::new();
    framing.encode(&[0x07], b"123456789", &mut out).unwrap();
    let mut expected = vec![0xAA, 0x55, 0x07, 0x09, 0x00];
    expected.extend_from_slice(b"123456789");
    expected.extend_from_slice(&[0x29, 0xB1]);
    assert_eq!(out, expected);
    let (frames, counters) =
        decode_every_way(&|| Box::new(LengthDecoder::new(vendor_framing(64))), &out);
    assert_eq!(frames, [expected.clone()]);
    assert_eq!(framing.payload(&frames[0]), b"123456789");
    assert_eq!(counters, clean(1));
}

/// A CCSDS-like field: big-endian, 1 octet, counting "octets after the field − 1"
/// (`adjust` = 1), CRC-32 little-endian over the whole frame from the sync. Payload 3 octets
/// + check 4 = 7 after the field, written as 6.
#[test]
fn a_length_field_counting_octets_minus_one_after_it() {
    let framing = LengthFraming::new(LengthFramingConfig {
        sync: vec![0x1A, 0xCF, 0xFC, 0x1D],
        length: LengthField {
            offset_bytes: 4,
            width_bytes: 1,
            order: ByteOrder::BigEndian,
            counts: LengthCounts::AfterField,
            adjust: 1,
        },
        check: Some(FrameCheck {
            checksum: crc(CRC32),
            order: ByteOrder::LittleEndian,
        }),
        check_from_bytes: 0,
        max_frame_bytes: 32,
    })
    .unwrap();
    let mut out = Vec::new();
    framing.encode(&[], &[1, 2, 3], &mut out).unwrap();
    assert_eq!(&out[..8], &[0x1A, 0xCF, 0xFC, 0x1D, 6, 1, 2, 3]);
    let crc32 = Crc::new(CRC32).unwrap().checksum(&out[..8]);
    assert_eq!(&out[8..], &crc32.to_le_bytes());
}

/// A whole-frame count: sync 1 + field 1 + payload + Sum8 1. A value of 2 (below the 3
/// octets of header and check) is a bad length; 200 is above the 16-octet maximum.
#[test]
fn impossible_lengths_are_counted_and_the_next_frame_found() {
    let make = || {
        LengthFraming::new(LengthFramingConfig {
            sync: vec![0xEB],
            length: LengthField {
                offset_bytes: 1,
                width_bytes: 1,
                order: ByteOrder::BigEndian,
                counts: LengthCounts::WholeFrame,
                adjust: 0,
            },
            check: Some(FrameCheck {
                checksum: Checksum::Sum8,
                order: ByteOrder::BigEndian,
            }),
            check_from_bytes: 0,
            max_frame_bytes: 16,
        })
        .unwrap()
    };
    let mut good = Vec::new();
    make().encode(&[], &[0x10, 0x20], &mut good).unwrap();
    // EB 05 10 20 (0xEB + 5 + 0x10 + 0x20 = 0x120 → 0x20).
    assert_eq!(good, [0xEB, 0x05, 0x10, 0x20, 0x20]);
    let mut stream = vec![0xEB, 0x02, 0xEB, 200];
    stream.extend_from_slice(&good);
    let (frames, counters) = decode_every_way(&|| Box::new(LengthDecoder::new(make())), &stream);
    assert_eq!(frames, [good.clone()]);
    // 0xEB 0x02: bad length, its first octet dropped; 0x02 garbage; 0xEB 200: oversize; 200
    // garbage.
    assert_eq!(
        counters,
        DecodeCounters {
            garbage_bytes: 2,
            bad_length: 1,
            oversize: 1,
            ..clean(1)
        }
    );
}

/// Garbage, a frame cut short by the next one, a frame with a corrupted payload, then a good
/// frame: the truncated frame's length swallows the next frame's start, fails its CRC, and
/// the rescan finds the next frame inside it.
#[test]
fn sync_length_resynchronises_after_garbage_truncation_and_corruption() {
    let framing = vendor_framing(64);
    let frame = |payload: &[u8]| {
        let mut out = Vec::new();
        framing.encode(&[0x01], payload, &mut out).unwrap();
        out
    };
    let (a, b, c) = (frame(b"first"), frame(b"second"), frame(b"third"));
    let mut stream = b"noise".to_vec();
    stream.extend_from_slice(&a[..7]);
    stream.extend_from_slice(&b);
    let mut corrupted = c.clone();
    corrupted[6] ^= 0xFF;
    stream.extend_from_slice(&corrupted);
    stream.extend_from_slice(&c);
    let (frames, counters) = decode_every_way(
        &|| Box::new(LengthDecoder::new(vendor_framing(64))),
        &stream,
    );
    assert_eq!(frames, [b.clone(), c.clone()]);
    assert_eq!(counters.frames, 2);
    assert_eq!(counters.bad_checksum, 2);
    // "noise" (5), the truncated frame's 6 octets after its first, the corrupted 12-octet
    // frame's 11 after its first: none holds 0xAA 0x55.
    assert_eq!(counters.garbage_bytes, 5 + 6 + 11);
}

#[test]
fn a_flood_of_sync_octets_costs_no_memory_and_is_counted() {
    let mut stream = vec![0xAA; 10_000];
    let mut good = Vec::new();
    vendor_framing(64)
        .encode(&[0x02], b"ok", &mut good)
        .unwrap();
    stream.extend_from_slice(&good);
    let (frames, counters) = decode_every_way(
        &|| Box::new(LengthDecoder::new(vendor_framing(64))),
        &stream,
    );
    assert_eq!(frames, [good]);
    // Each 0xAA is followed by 0xAA (not 0x55) except the last, followed by the frame's 0xAA.
    assert_eq!(counters.garbage_bytes, 10_000);
    assert_eq!(counters.rejected_frames(), 0);
}

#[test]
fn sync_length_layouts_that_cannot_work_are_refused() {
    let base = vendor_framing(64).config().clone();
    let err = LengthFraming::new(LengthFramingConfig {
        sync: vec![],
        ..base.clone()
    })
    .unwrap_err();
    assert_eq!(err, FramingError::EmptySync);
    let length = LengthField {
        width_bytes: 3,
        ..base.length
    };
    let err = LengthFraming::new(LengthFramingConfig {
        length,
        ..base.clone()
    })
    .unwrap_err();
    assert_eq!(
        err.to_string(),
        "length field width 3 octets: must be 1, 2 or 4"
    );
    let length = LengthField {
        offset_bytes: 1,
        ..base.length
    };
    assert!(matches!(
        LengthFraming::new(LengthFramingConfig {
            length,
            ..base.clone()
        }),
        Err(FramingError::LengthInsideSync {
            offset_bytes: 1,
            sync_len_bytes: 2
        })
    ));
    let err = LengthFraming::new(LengthFramingConfig {
        max_frame_bytes: 6,
        ..base.clone()
    })
    .unwrap_err();
    assert_eq!(
        err,
        FramingError::MaxFrameTooSmall {
            max_bytes: 6,
            min_bytes: 7
        }
    );
    let err = LengthFraming::new(LengthFramingConfig {
        check_from_bytes: 6,
        ..base
    })
    .unwrap_err();
    assert!(matches!(
        err,
        FramingError::CheckFromBeyondHeader {
            check_from_bytes: 6,
            header_len_bytes: 5
        }
    ));
}

#[test]
fn sync_length_encoder_refuses_what_it_cannot_send() {
    let framing = vendor_framing(16);
    let mut out = Vec::new();
    let err = framing.encode(&[], b"x", &mut out).unwrap_err();
    assert_eq!(
        err,
        FramingError::HeaderLength {
            expected_bytes: 1,
            got_bytes: 0
        }
    );
    let err = framing.encode(&[0], &[0; 10], &mut out).unwrap_err();
    assert_eq!(
        err,
        FramingError::PayloadTooLong {
            payload_bytes: 10,
            frame_bytes: 17,
            max_bytes: 16
        }
    );
    assert!(out.is_empty());
    // A 1-octet field cannot count 300 octets.
    let one_octet = LengthFraming::new(LengthFramingConfig {
        length: LengthField {
            width_bytes: 1,
            offset_bytes: 2,
            ..vendor_framing(16).config().length
        },
        check_from_bytes: 0,
        max_frame_bytes: 1000,
        ..vendor_framing(16).config().clone()
    })
    .unwrap();
    let err = one_octet.encode(&[], &[0; 300], &mut out).unwrap_err();
    assert_eq!(
        err,
        FramingError::LengthDoesNotFit {
            value: 300,
            width_bytes: 1
        }
    );
}

// --- Every framing: random round trips and hostile input ---

type Encoder = Box<dyn Fn(&[u8], &mut Vec<u8>)>;
type Maker = Box<dyn Fn() -> Box<dyn StreamDecoder>>;

fn encoder(f: impl Fn(&[u8], &mut Vec<u8>) + 'static) -> Encoder {
    Box::new(f)
}

fn maker<D: StreamDecoder + 'static>(f: impl Fn() -> D + 'static) -> Maker {
    Box::new(move || Box::new(f()))
}

/// Each framing's encoder and decoder, for payloads up to 300 octets; the sync-and-length
/// decoder delivers whole frames, so its payload is taken back out by the caller. Its CRC
/// covers the whole frame, so that no corrupted octet can pass.
fn all_framings() -> Vec<(&'static str, Encoder, Maker)> {
    let hdlc = HdlcFraming {
        fcs: Some(FrameCheck {
            checksum: crc(CRC32),
            order: ByteOrder::LittleEndian,
        }),
        accm: 0xFFFF_FFFF,
    };
    let hdlc_decoder = hdlc.clone();
    vec![
        (
            "slip",
            encoder(slip::encode),
            maker(|| SlipDecoder::new(300)),
        ),
        (
            "cobs",
            encoder(cobs::encode),
            maker(|| CobsDecoder::new(300)),
        ),
        (
            "hdlc",
            encoder(move |p, out| hdlc.encode(p, out)),
            maker(move || HdlcDecoder::new(&hdlc_decoder, 300)),
        ),
        (
            "length",
            encoder(|p, out| {
                vendor_framing_checked_from(0, 307)
                    .encode(&[0x09], p, out)
                    .unwrap()
            }),
            maker(|| LengthDecoder::new(vendor_framing_checked_from(0, 307))),
        ),
    ]
}

#[test]
fn random_payloads_round_trip_through_every_framing_in_any_chunks() {
    for (name, encode, make) in all_framings() {
        let mut rng = SplitMix64::new(0x5EED_0001);
        let payloads = random_payloads(&mut rng, 200, 300);
        let mut stream = Vec::new();
        for p in &payloads {
            encode(p, &mut stream);
        }
        let (mut frames, counters) = decode_every_way(&*make, &stream);
        if name == "length" {
            frames = frames
                .iter()
                .map(|f| vendor_framing(307).payload(f).to_vec())
                .collect();
        }
        assert_eq!(frames, payloads, "{name}");
        assert_eq!(counters, clean(200), "{name}");
    }
}

#[test]
fn random_text_lines_round_trip() {
    let mut rng = SplitMix64::new(0x5EED_0002);
    let lines: Vec<Vec<u8>> = (0..200)
        .map(|_| {
            (0..1 + rng.below(80))
                .map(|_| 0x20 + rng.below(95) as u8)
                .collect()
        })
        .collect();
    let mut stream = Vec::new();
    for (i, line) in lines.iter().enumerate() {
        lines::encode(
            line,
            if i % 2 == 0 {
                LineEnding::CrLf
            } else {
                LineEnding::Lf
            },
            &mut stream,
        )
        .unwrap();
    }
    let (frames, counters) = decode_every_way(&|| Box::new(LineDecoder::new(80)), &stream);
    assert_eq!(frames, lines);
    assert_eq!(counters.frames, 200);
}

/// Random octets, truncated and corrupted frames and floods between good frames: every good
/// frame that was not damaged comes out, nothing is delivered twice, chunking changes nothing,
/// and every delivered frame is one that was sent.
#[test]
fn hostile_streams_never_deliver_what_was_not_sent() {
    for (name, encode, make) in all_framings() {
        let mut rng = SplitMix64::new(0x5EED_0003);
        let mut stream = Vec::new();
        let mut sent = Vec::new();
        for _ in 0..300 {
            let len = 1 + rng.below(40);
            let payload = rng.bytes(len);
            let mut frame = Vec::new();
            encode(&payload, &mut frame);
            match rng.below(6) {
                0 => {
                    let len = rng.below(50);
                    stream.extend(rng.bytes(len));
                }
                // Cut before its last two octets: an HDLC frame cut of its closing flag alone
                // is still whole (the next flag closes it).
                1 => stream.extend_from_slice(&frame[..rng.below(frame.len() - 1)]),
                2 => {
                    let at = rng.below(frame.len());
                    frame[at] ^= 1 << rng.below(8);
                    stream.extend_from_slice(&frame);
                }
                3 => stream.extend(std::iter::repeat_n(frame[0], rng.below(400))),
                _ => {
                    stream.extend_from_slice(&frame);
                    sent.push(payload);
                }
            }
        }
        let (mut frames, counters) = decode_every_way(&*make, &stream);
        if name == "length" {
            frames = frames
                .iter()
                .map(|f| vendor_framing(307).payload(f).to_vec())
                .collect();
        }
        assert!(
            counters.rejected_frames() + counters.garbage_bytes > 0,
            "{name}: {counters:?}"
        );
        // No CRC-less framing can tell a corrupted payload from a good one, so only the
        // checked framings are held to "nothing but what was sent".
        if matches!(name, "hdlc" | "length") {
            let mut expected = sent.iter();
            for f in &frames {
                assert!(
                    expected.any(|s| s == f),
                    "{name}: delivered a frame that was not sent intact, in order"
                );
            }
        }
        assert_eq!(counters.frames as usize, frames.len(), "{name}");
    }
}
