//! The crate's error type: a broken link, a missing firmware or QEMU, a target's refusal, a
//! malformed cycle recording.

/// Environment variable naming the PIL firmware ELF.
pub const FIRMWARE_ENV: &str = "TVMD_PIL_FIRMWARE";
/// The command that builds the PIL firmware.
pub const BUILD_COMMAND: &str = "bash scripts/pil.sh build";

/// Errors of a processor-in-the-loop flight.
#[derive(Debug, thiserror::Error)]
pub enum PilError {
    /// No such target.
    #[error("unknown PIL target `{0}` (known: cortex-m4, cortex-m7)")]
    UnknownTarget(String),
    /// The firmware ELF was not found.
    #[error(
        "PIL firmware not found (looked for {searched}); build it with `{BUILD_COMMAND}`, or \
         set {FIRMWARE_ENV} to its ELF"
    )]
    FirmwareMissing {
        /// The paths looked at.
        searched: String,
    },
    /// `qemu-system-arm` is not on `PATH`.
    #[error(
        "`qemu-system-arm` not found on PATH: install it (Debian/Ubuntu: `sudo apt-get install \
         qemu-system-arm`; `bash scripts/target.sh` installs it too)"
    )]
    QemuMissing,
    /// Starting or talking to QEMU failed.
    #[error("I/O error on the PIL link: {0}")]
    Io(#[from] std::io::Error),
    /// No complete frame arrived in time.
    #[error("no answer in time")]
    Timeout,
    /// QEMU closed the link (it exited).
    #[error("the link closed")]
    Closed,
    /// A frame's checksum is wrong.
    #[error("frame checksum mismatch (received {got:#010x}, computed {want:#010x})")]
    Checksum {
        /// CRC-32 in the frame.
        got: u32,
        /// CRC-32 of the frame's bytes.
        want: u32,
    },
    /// Bytes that are not the expected frame: the two sides are out of step.
    #[error("link desynchronised: {0}")]
    Desync(String),
    /// The target refused a request (malformed, out of order, or a configuration it cannot
    /// build).
    #[error("the target reported: {0}")]
    Target(String),
    /// A link error, with what the host was doing and QEMU's state.
    #[error("{target}: {during}: {source} ({qemu})")]
    Link {
        /// The target's label.
        target: String,
        /// What the host waited for.
        during: String,
        /// The error.
        #[source]
        source: Box<PilError>,
        /// QEMU's status and stderr.
        qemu: String,
    },
    /// A cycle recording's bytes that are not one.
    #[error("cycle recording: {0}")]
    Recording(String),
}
