//! A committed recording opened: its header checked and its controller built from its
//! configuration words (shared by the target tests' replay and the cost firmware's timing of
//! the same flights).

use tvmd_wire::{self as wire, Reader, WireController, AGENTS};

/// Words `at..at + len` of a recording (little-endian), in a `K`-word buffer.
pub fn words<const K: usize>(recording: &[u8], at: usize, len: usize) -> Option<[u32; K]> {
    let mut w = [0u32; K];
    let bytes = recording.get(4 * at..4 * (at + len))?;
    for (slot, c) in w.iter_mut().zip(bytes.chunks_exact(4)) {
        *slot = u32::from_le_bytes([c[0], c[1], c[2], c[3]]);
    }
    Some(w)
}

/// A recording's layout and a fresh controller of its configuration.
pub struct Opened {
    /// Agents.
    pub n: usize,
    /// Cycles recorded.
    pub cycles: usize,
    /// The first cycle's word.
    pub start: usize,
    /// Words per cycle.
    pub len: usize,
    /// The controller the recording's configuration builds.
    pub controller: WireController,
}

/// Opens `recording`; `Err` names what is wrong with it.
pub fn open(recording: &[u8]) -> Result<Opened, &'static str> {
    let [magic, version, n, cycles, c] =
        words::<{ wire::RECORDING_HEADER_WORDS }>(recording, 0, wire::RECORDING_HEADER_WORDS)
            .ok_or("truncated header")?;
    if magic != wire::RECORDING_MAGIC || version != wire::RECORDING_VERSION {
        return Err("not a recording of this version");
    }
    let (n, cycles, c) = (n as usize, cycles as usize, c as usize);
    let config_words =
        words::<{ wire::config_words(AGENTS) }>(recording, wire::RECORDING_HEADER_WORDS, c)
            .ok_or("truncated configuration")?;
    let config = wire::CoreConfig::get(&mut Reader::new(config_words.get(..c).ok_or("config")?))
        .filter(|k| k.n == n)
        .ok_or("malformed configuration")?;
    let controller = config
        .build()
        .map_err(|_| "configuration refused by the core")?;
    let len = wire::cycle_words(n);
    let start = wire::RECORDING_HEADER_WORDS + c;
    if recording.len() != 4 * (start + cycles * len) {
        return Err("length does not match the header");
    }
    Ok(Opened {
        n,
        cycles,
        start,
        len,
        controller,
    })
}
