//! PIL frames on the host side (layout in `control::wire`): encoding, and reading one frame
//! from a byte stream before a deadline, with the checksum and framing checked.

use std::collections::VecDeque;
use std::sync::mpsc::{Receiver, RecvTimeoutError};
use std::time::Instant;

use crate::error::PilError;
use tvmd_wire::{frame_crc, frame_header, FRAME_HEADER_BYTES, FRAME_MAGIC, MAX_PAYLOAD_BYTES};

/// One frame: kind, sequence number, payload.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Frame {
    /// What the frame carries (`wire::KIND_*`).
    pub kind: u16,
    /// The request's sequence number (a reply echoes it).
    pub seq: u16,
    /// Payload bytes (a whole number of words).
    pub payload: Vec<u8>,
}

impl Frame {
    /// The payload as little-endian words.
    pub fn words(&self) -> Vec<u32> {
        self.payload
            .chunks_exact(4)
            .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]))
            .collect()
    }

    /// The payload after `skip` words as text (trailing zero padding removed).
    pub fn text(&self, skip: usize) -> String {
        let bytes = self.payload.get(4 * skip..).unwrap_or(&[]);
        let end = bytes.iter().rposition(|b| *b != 0).map_or(0, |i| i + 1);
        String::from_utf8_lossy(&bytes[..end]).into_owned()
    }
}

/// Little-endian bytes of words.
pub fn bytes_of(words: &[u32]) -> Vec<u8> {
    words.iter().flat_map(|w| w.to_le_bytes()).collect()
}

/// The bytes of a frame. `payload` must be a whole number of words of at most
/// `MAX_PAYLOAD_BYTES` (the host's own requests always are).
pub fn encode(kind: u16, seq: u16, payload: &[u8]) -> Result<Vec<u8>, PilError> {
    if payload.len() % 4 != 0 || payload.len() > MAX_PAYLOAD_BYTES {
        return Err(PilError::Desync(format!(
            "payload of {} bytes cannot be framed",
            payload.len()
        )));
    }
    let header = frame_header(kind, seq, payload.len() as u32);
    let mut out = Vec::with_capacity(FRAME_HEADER_BYTES + payload.len() + 4);
    out.extend_from_slice(&header);
    out.extend_from_slice(payload);
    out.extend_from_slice(&frame_crc(&header, payload).to_le_bytes());
    Ok(out)
}

/// Bytes arriving from the target.
pub trait ByteSource {
    /// Fills `buf` completely before `deadline`, or fails ([`PilError::Timeout`] when the
    /// deadline passes, [`PilError::Closed`] when the stream ends).
    fn read_exact(&mut self, buf: &mut [u8], deadline: Instant) -> Result<(), PilError>;
}

/// A [`ByteSource`] fed by chunks sent over a channel (by the thread reading QEMU's stdout).
#[derive(Debug)]
pub struct ChannelSource {
    rx: Receiver<Vec<u8>>,
    pending: VecDeque<u8>,
}

impl ChannelSource {
    /// Reads the chunks `rx` receives.
    pub fn new(rx: Receiver<Vec<u8>>) -> Self {
        Self {
            rx,
            pending: VecDeque::new(),
        }
    }
}

impl ByteSource for ChannelSource {
    fn read_exact(&mut self, buf: &mut [u8], deadline: Instant) -> Result<(), PilError> {
        for b in buf.iter_mut() {
            while self.pending.is_empty() {
                let left = deadline.saturating_duration_since(Instant::now());
                match self.rx.recv_timeout(left) {
                    Ok(chunk) => self.pending.extend(chunk),
                    Err(RecvTimeoutError::Timeout) => return Err(PilError::Timeout),
                    Err(RecvTimeoutError::Disconnected) => return Err(PilError::Closed),
                }
            }
            // Not empty: checked above.
            *b = self.pending.pop_front().unwrap_or(0);
        }
        Ok(())
    }
}

/// Reads one frame before `deadline`: a wrong magic or an impossible length is a desync, a
/// wrong CRC a [`PilError::Checksum`].
pub fn read_frame(src: &mut dyn ByteSource, deadline: Instant) -> Result<Frame, PilError> {
    let mut header = [0u8; FRAME_HEADER_BYTES];
    src.read_exact(&mut header, deadline)?;
    if header[..4] != FRAME_MAGIC {
        return Err(PilError::Desync(format!(
            "expected a frame, received {:?}",
            String::from_utf8_lossy(&header)
        )));
    }
    let kind = u16::from_le_bytes([header[4], header[5]]);
    let seq = u16::from_le_bytes([header[6], header[7]]);
    let len = u32::from_le_bytes([header[8], header[9], header[10], header[11]]) as usize;
    if len % 4 != 0 || len > MAX_PAYLOAD_BYTES {
        return Err(PilError::Desync(format!(
            "frame announces a payload of {len} bytes"
        )));
    }
    let mut payload = vec![0u8; len];
    src.read_exact(&mut payload, deadline)?;
    let mut crc = [0u8; 4];
    src.read_exact(&mut crc, deadline)?;
    let got = u32::from_le_bytes(crc);
    let want = frame_crc(&header, &payload);
    if got != want {
        return Err(PilError::Checksum { got, want });
    }
    Ok(Frame { kind, seq, payload })
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::mpsc::channel;
    use std::time::Duration;

    fn soon() -> Instant {
        Instant::now() + Duration::from_secs(5)
    }

    fn source_of(chunks: &[&[u8]]) -> (ChannelSource, std::sync::mpsc::Sender<Vec<u8>>) {
        let (tx, rx) = channel();
        for c in chunks {
            tx.send(c.to_vec()).unwrap();
        }
        (ChannelSource::new(rx), tx)
    }

    #[test]
    fn frames_round_trip_across_chunk_boundaries() {
        let payload = bytes_of(&[1, 0xdead_beef, f32::to_bits(-0.5)]);
        let bytes = encode(3, 513, &payload).unwrap();
        let (a, b) = bytes.split_at(7);
        let (mut src, _tx) = source_of(&[a, b, &encode(0x80, 0, &[]).unwrap()]);
        let f = read_frame(&mut src, soon()).unwrap();
        assert_eq!((f.kind, f.seq), (3, 513));
        assert_eq!(f.words(), [1, 0xdead_beef, f32::to_bits(-0.5)]);
        let g = read_frame(&mut src, soon()).unwrap();
        assert_eq!((g.kind, g.seq, g.payload.len()), (0x80, 0, 0));
    }

    #[test]
    fn text_payload_drops_the_padding() {
        let mut payload = bytes_of(&[7]);
        payload.extend_from_slice(b"refused\0");
        let f = Frame {
            kind: 0x85,
            seq: 1,
            payload,
        };
        assert_eq!(f.text(1), "refused");
        assert_eq!(f.text(9), "");
    }

    #[test]
    fn a_corrupted_byte_fails_the_checksum() {
        let mut bytes = encode(3, 1, &bytes_of(&[42, 43])).unwrap();
        bytes[13] ^= 0x10;
        let (mut src, _tx) = source_of(&[&bytes]);
        let e = read_frame(&mut src, soon()).unwrap_err();
        assert!(matches!(e, PilError::Checksum { .. }), "{e}");
        // A corrupted header (kind) too: the CRC covers it.
        let mut bytes = encode(3, 1, &[]).unwrap();
        bytes[4] = 2;
        let (mut src, _tx) = source_of(&[&bytes]);
        assert!(matches!(
            read_frame(&mut src, soon()),
            Err(PilError::Checksum { .. })
        ));
    }

    #[test]
    fn stray_text_or_a_bad_length_is_a_desync() {
        let (mut src, _tx) = source_of(&[b"panicked at src/x.rs"]);
        let e = read_frame(&mut src, soon()).unwrap_err();
        assert!(
            matches!(&e, PilError::Desync(m) if m.contains("panicked")),
            "{e}"
        );
        let mut bytes = encode(3, 1, &[]).unwrap();
        bytes[8..12].copy_from_slice(&3u32.to_le_bytes());
        let (mut src, _tx) = source_of(&[&bytes]);
        assert!(matches!(
            read_frame(&mut src, soon()),
            Err(PilError::Desync(_))
        ));
        assert!(encode(1, 1, &[0; 3]).is_err());
        assert!(encode(1, 1, &vec![0; MAX_PAYLOAD_BYTES + 4]).is_err());
    }

    #[test]
    fn silence_times_out_and_a_closed_stream_is_reported() {
        let bytes = encode(3, 1, &bytes_of(&[1, 2])).unwrap();
        // Half a frame, then nothing (the sender stays alive): a timeout, not a hang.
        let (mut src, _tx) = source_of(&[&bytes[..10]]);
        let e = read_frame(&mut src, Instant::now() + Duration::from_millis(50)).unwrap_err();
        assert!(matches!(e, PilError::Timeout), "{e}");
        let (mut src, tx) = source_of(&[&bytes[..10]]);
        drop(tx);
        let e = read_frame(&mut src, soon()).unwrap_err();
        assert!(matches!(e, PilError::Closed), "{e}");
    }

    #[test]
    fn crc32_matches_the_standard_check_value() {
        // The CRC-32 check value of "123456789".
        let crc = !tvmd_wire::crc32_update(!0, b"123456789");
        assert_eq!(crc, 0xcbf4_3926);
    }
}
