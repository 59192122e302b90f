//! Processor-in-the-loop frames.

// Processor-in-the-loop frames: `FRAME_MAGIC`, kind (u16), sequence number (u16), payload
// length in bytes (u32, a multiple of 4, at most `MAX_PAYLOAD_BYTES`), the payload, and the
// CRC-32 of everything after the magic. Each host frame gets exactly one reply echoing its
// sequence number; the target sends `KIND_READY` once at boot.

/// First bytes of every frame.
pub const FRAME_MAGIC: [u8; 4] = *b"TVPL";
/// Bytes before the payload (magic, kind, sequence, length).
pub const FRAME_HEADER_BYTES: usize = 12;
/// Largest payload of a frame.
pub const MAX_PAYLOAD_BYTES: usize = 2048;
/// Protocol version, the payload of `KIND_READY` (2: the configuration carries the law and
/// `KIND_SET_LANDED` exists; 3: the configuration carries the fault detection and the round
/// cap, and a cycle's answer ends with its [`crate::FaultAnswer`]).
pub const PROTOCOL_VERSION: u32 = 3;
/// Host: configure the controller ([`crate::CoreConfig`] words). Reply `KIND_CONFIGURED` or
/// `KIND_REFUSED`.
pub const KIND_CONFIGURE: u16 = 1;
/// Host: set the failure mask (one word of [`crate::mask_bits`]). Reply `KIND_HOVER` or
/// `KIND_REFUSED`.
pub const KIND_SET_FAILURES: u16 = 2;
/// Host: one cycle ([`crate::INPUT_WORDS`] words). Reply `KIND_OUTPUT` or `KIND_SKIPPED`.
pub const KIND_STEP: u16 = 3;
/// Host: the landed hold (one word, 0 or 1: `Controller::set_landed`). Reply `KIND_LANDED`.
pub const KIND_SET_LANDED: u16 = 4;
/// Target: booted (one word, [`PROTOCOL_VERSION`]).
pub const KIND_READY: u16 = 0x80;
/// Target: controller built (the agent count).
pub const KIND_CONFIGURED: u16 = 0x81;
/// Target: mask accepted ([`crate::put_hover`] words).
pub const KIND_HOVER: u16 = 0x82;
/// Target: the cycle's output ([`crate::put_output`] words, then the [`crate::put_fault_answer`] words).
pub const KIND_OUTPUT: u16 = 0x83;
/// Target: the cycle was skipped (held commands, [`crate::put_commands`] words, the
/// [`crate::put_fault_answer`] words, then the message).
pub const KIND_SKIPPED: u16 = 0x84;
/// Target: configuration or mask refused (the message).
pub const KIND_REFUSED: u16 = 0x85;
/// Target: the request was malformed or arrived out of order (the message).
pub const KIND_ERROR: u16 = 0x86;
/// Target: the landed hold is set (one word, its value).
pub const KIND_LANDED: u16 = 0x87;

/// The header of a frame.
pub fn frame_header(kind: u16, seq: u16, payload_bytes: u32) -> [u8; FRAME_HEADER_BYTES] {
    let mut h = [0u8; FRAME_HEADER_BYTES];
    let (magic, rest) = h.split_at_mut(4);
    magic.copy_from_slice(&FRAME_MAGIC);
    let (k, rest) = rest.split_at_mut(2);
    k.copy_from_slice(&kind.to_le_bytes());
    let (s, len) = rest.split_at_mut(2);
    s.copy_from_slice(&seq.to_le_bytes());
    len.copy_from_slice(&payload_bytes.to_le_bytes());
    h
}

/// The CRC-32 of a frame: over the header after the magic, then the payload.
pub fn frame_crc(header: &[u8; FRAME_HEADER_BYTES], payload: &[u8]) -> u32 {
    let tail = header.get(4..).unwrap_or(&[]);
    !crc32_update(crc32_update(!0, tail), payload)
}

/// CRC-32 (IEEE 802.3, reflected, as zlib's `crc32`): `!crc32_update(!0, bytes)`.
/// Hand-written, bitwise: this file is shared with the firmware, which has no dependency for
/// it, and frames are short.
pub fn crc32_update(crc: u32, bytes: &[u8]) -> u32 {
    bytes.iter().fold(crc, |crc, b| {
        (0..8).fold(crc ^ u32::from(*b), |c, _| {
            if c & 1 != 0 {
                (c >> 1) ^ 0xedb8_8320
            } else {
                c >> 1
            }
        })
    })
}
