//! The frames of one device not yet on the line, in order, each with the instant it may go.
//!
//! In real time a frame due at a tick goes out its device's declared latency after the tick's
//! telemetry arrived; on a line with a baud rate it goes once its last byte would have crossed
//! the line (10 bits per byte: a start bit, 8 data bits, a stop bit), after the frames before
//! it. In lockstep every frame may go at once. A frame the line cannot take yet waits (a full
//! pseudo-terminal or socket buffer); the outbox holds at most its capacity in bytes, and a
//! frame beyond it is dropped whole and counted. Bytes for a line with no driver are lost, as
//! on an unplugged serial line, and counted.

use std::collections::VecDeque;
use std::time::{Duration, Instant};

use super::Endpoint;

/// Bits on the line per byte of an 8N1 UART: start, 8 data, stop.
const BITS_PER_BYTE: u64 = 10;

/// What became of the frames.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct OutboxCounters {
    /// Frames written whole to the line.
    pub frames_sent: u64,
    /// Bytes written to the line.
    pub bytes_sent: u64,
    /// Frames lost because no driver was there.
    pub frames_unheard: u64,
    /// Frames dropped because the outbox was full (the driver does not read).
    pub frames_dropped_full: u64,
}

/// Frames waiting for their instant or for room on the line.
#[derive(Debug)]
pub struct Outbox {
    bytes: VecDeque<u8>,
    /// Each frame's length and the instant it may go, in order.
    frames: VecDeque<(usize, Instant)>,
    /// Bytes of the head frame already written.
    head_sent: usize,
    capacity: usize,
    baud: Option<u32>,
    line_free_at: Option<Instant>,
    counters: OutboxCounters,
}

impl Outbox {
    /// An empty outbox of `capacity` bytes for a line of `baud` (none: no transmission time).
    pub fn new(capacity: usize, baud: Option<u32>) -> Self {
        Self {
            bytes: VecDeque::with_capacity(capacity),
            frames: VecDeque::with_capacity(64),
            head_sent: 0,
            capacity,
            baud,
            line_free_at: None,
            counters: OutboxCounters::default(),
        }
    }

    /// Queues `frame`, to go no sooner than `earliest` and, when `paced` (real time) on a line
    /// with a baud rate, once its bytes would have crossed the line after those before it.
    pub fn push(&mut self, frame: &[u8], earliest: Instant, paced: bool) {
        if frame.is_empty() {
            return;
        }
        if self.bytes.len() + frame.len() > self.capacity {
            self.counters.frames_dropped_full += 1;
            return;
        }
        let at = match self.baud {
            Some(b) if b > 0 && paced => {
                let start = self.line_free_at.map_or(earliest, |f| f.max(earliest));
                let ns = frame.len() as u64 * BITS_PER_BYTE * 1_000_000_000 / u64::from(b);
                let done = start + Duration::from_nanos(ns);
                self.line_free_at = Some(done);
                done
            }
            _ => earliest,
        };
        self.bytes.extend(frame);
        self.frames.push_back((frame.len(), at));
    }

    /// The instant the next frame may go, if one waits.
    pub fn next_due(&self) -> Option<Instant> {
        self.frames.front().map(|(_, at)| *at)
    }

    /// Whether nothing waits.
    pub fn is_empty(&self) -> bool {
        self.frames.is_empty()
    }

    /// Writes every frame whose instant has come, in order, as far as the line takes them.
    /// With no driver there, those frames are lost (counted).
    pub fn flush(&mut self, now: Instant, endpoint: &mut Endpoint) -> std::io::Result<()> {
        while let Some(&(len, at)) = self.frames.front() {
            if at > now {
                break;
            }
            // The head frame's unsent bytes, contiguous (rotating the ring in place).
            let pending = &self.bytes.make_contiguous()[self.head_sent..len];
            match endpoint.write(pending)? {
                None => {
                    self.counters.frames_unheard += 1;
                    self.pop_head(len);
                }
                Some(n) if n == pending.len() => {
                    self.counters.frames_sent += 1;
                    self.counters.bytes_sent += n as u64;
                    self.pop_head(len);
                }
                Some(n) => {
                    // The line took part of it: the rest when there is room.
                    self.counters.bytes_sent += n as u64;
                    self.head_sent += n;
                    break;
                }
            }
        }
        Ok(())
    }

    fn pop_head(&mut self, len: usize) {
        self.bytes.drain(..len);
        self.frames.pop_front();
        self.head_sent = 0;
    }

    /// What became of the frames so far.
    pub fn counters(&self) -> OutboxCounters {
        self.counters
    }
}
