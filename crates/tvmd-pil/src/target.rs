//! Processor-in-the-loop (issue 14): the f32 core's cycle executed by the PIL firmware
//! (`embedded/target-tests`, bin `tvmd-pil`) on an emulated Cortex-M4F (QEMU `mps2-an386`) or
//! Cortex-M7 (`mps2-an500`), while the simulator keeps the physics.
//!
//! [`PilCore`] is a [`CoreEngine`]`<f32>`: the simulator's controller adapter drives it exactly as it
//! drives the in-process core (failure masks, landing, diagnostics). Over QEMU's first serial
//! port (the boards' CMSDK UART0, on QEMU's stdin/stdout) the host sends the controller's
//! configuration once ([`CoreConfig`]), then a failure mask when it changes and each period's
//! state and reference, all as exact f32 bits in CRC-checked frames (layout in module `wire`);
//! the target answers every request with the core's answer (the whole `ControlOutput`, a
//! skipped cycle's held commands and message, a mask's hover classification or refusal). A
//! wrong checksum, sequence number or frame kind is a [`PilError`], and so is silence beyond
//! [`CYCLE_TIMEOUT`]: a broken link ends the run with an error, never a hang.

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use tvmd_core::{FailureMask, FaultMasking, FaultReport, Reference, RigidState};

use crate::engine::{BoxedError, CoreEngine, CycleAnswer, FailureAnswer, SkippedCycle, MAX_AGENTS};
use crate::error::{PilError, BUILD_COMMAND, FIRMWARE_ENV};
use crate::frame;
use crate::link::QemuLink;
use tvmd_wire::{self as wire, CoreConfig, Reader, Writer};

/// Longest wait for the firmware to boot and for the configuration's answer.
pub const START_TIMEOUT: Duration = Duration::from_secs(30);
/// Longest wait for the answer to one request (a cycle takes well under a millisecond of
/// emulated time; the margin is for a loaded machine).
pub const CYCLE_TIMEOUT: Duration = Duration::from_secs(10);

/// An emulated target.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum PilTarget {
    /// Cortex-M4F, QEMU `mps2-an386`.
    CortexM4,
    /// Cortex-M7, QEMU `mps2-an500`.
    CortexM7,
}

impl PilTarget {
    /// Every target.
    pub const ALL: [Self; 2] = [Self::CortexM4, Self::CortexM7];

    /// `"cortex-m4"` or `"cortex-m7"`.
    pub const fn as_str(self) -> &'static str {
        match self {
            Self::CortexM4 => "cortex-m4",
            Self::CortexM7 => "cortex-m7",
        }
    }

    /// The QEMU machine.
    pub const fn machine(self) -> &'static str {
        match self {
            Self::CortexM4 => "mps2-an386",
            Self::CortexM7 => "mps2-an500",
        }
    }

    /// What a summary says flew: e.g. `"cortex-m4 (qemu mps2-an386)"`.
    pub fn label(self) -> String {
        format!("{} (qemu {})", self.as_str(), self.machine())
    }
}

impl std::fmt::Display for PilTarget {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

impl std::str::FromStr for PilTarget {
    type Err = PilError;

    fn from_str(s: &str) -> Result<Self, PilError> {
        Self::ALL
            .into_iter()
            .find(|t| t.as_str() == s)
            .ok_or_else(|| PilError::UnknownTarget(s.to_string()))
    }
}

/// Where the PIL firmware is looked for: [`FIRMWARE_ENV`] if set (and then only there), else
/// `$CARGO_TARGET_DIR` and the standard build directories of `embedded/target-tests` in this
/// repository.
pub fn firmware_candidates() -> Vec<PathBuf> {
    candidates_with(std::env::var_os(FIRMWARE_ENV))
}

/// [`firmware_candidates`] with [`FIRMWARE_ENV`] set to `env`.
fn candidates_with(env: Option<std::ffi::OsString>) -> Vec<PathBuf> {
    if let Some(p) = env {
        return vec![PathBuf::from(p)];
    }
    let rel = Path::new("thumbv7em-none-eabihf/release/tvmd-pil");
    let repo = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let mut dirs: Vec<PathBuf> = std::env::var_os("CARGO_TARGET_DIR")
        .map(PathBuf::from)
        .into_iter()
        .collect();
    dirs.push(repo.join("embedded/target-tests/target"));
    dirs.push(repo.join("target"));
    dirs.into_iter().map(|d| d.join(rel)).collect()
}

/// The PIL firmware ELF (see [`firmware_candidates`]).
pub fn firmware_path() -> Result<PathBuf, PilError> {
    first_file(&firmware_candidates())
}

fn first_file(candidates: &[PathBuf]) -> Result<PathBuf, PilError> {
    candidates
        .iter()
        .find(|p| p.is_file())
        .cloned()
        .ok_or_else(|| PilError::FirmwareMissing {
            searched: candidates
                .iter()
                .map(|p| p.display().to_string())
                .collect::<Vec<_>>()
                .join(", "),
        })
}

/// The f32 core running on an emulated target.
#[derive(Debug)]
pub struct PilCore {
    link: QemuLink,
    target: PilTarget,
    n: usize,
    failures: FailureMask<MAX_AGENTS>,
    /// The detector's report and masking of the last cycle, as the target answered them.
    fault: Option<wire::FaultAnswer>,
    seq: u16,
}

impl PilCore {
    /// Boots the firmware on `target` and builds the controller of `config` there.
    pub fn start(target: PilTarget, config: &CoreConfig) -> Result<Self, PilError> {
        let elf = firmware_path()?;
        let link = QemuLink::spawn(target.machine(), &elf)?;
        let mut core = Self {
            link,
            target,
            n: config.n,
            failures: FailureMask::none(),
            fault: None,
            seq: 0,
        };
        let ready = core.receive("the firmware's boot frame", START_TIMEOUT)?;
        if ready.kind != wire::KIND_READY || ready.words() != [wire::PROTOCOL_VERSION] {
            return Err(core.link_error(
                "the firmware's boot frame",
                PilError::Desync(format!(
                    "expected protocol {} (rebuild the firmware: `{BUILD_COMMAND}`)",
                    wire::PROTOCOL_VERSION
                )),
            ));
        }
        let mut words = [0u32; wire::config_words(MAX_AGENTS)];
        let mut w = Writer::new(&mut words);
        config
            .put(&mut w)
            .ok_or_else(|| PilError::Desync("configuration too large".into()))?;
        let len = w.len();
        let reply = core.request(wire::KIND_CONFIGURE, &words[..len], START_TIMEOUT)?;
        match reply.kind {
            wire::KIND_CONFIGURED => Ok(core),
            wire::KIND_REFUSED => Err(PilError::Target(format!(
                "configuration refused: {}",
                reply.text(0)
            ))),
            k => Err(core.unexpected("the configuration's answer", k)),
        }
    }

    /// The target flying.
    pub fn target(&self) -> PilTarget {
        self.target
    }

    fn link_error(&mut self, during: &str, source: PilError) -> PilError {
        PilError::Link {
            target: self.target.label(),
            during: during.to_string(),
            source: Box::new(source),
            qemu: self.link.diagnostics(),
        }
    }

    fn unexpected(&mut self, during: &str, kind: u16) -> PilError {
        self.link_error(
            during,
            PilError::Desync(format!("unexpected frame kind {kind:#x}")),
        )
    }

    fn receive(&mut self, during: &str, timeout: Duration) -> Result<frame::Frame, PilError> {
        match self.link.receive(Instant::now() + timeout) {
            Ok(f) if f.kind == wire::KIND_ERROR => Err(PilError::Target(f.text(0))),
            Ok(f) => Ok(f),
            Err(e) => Err(self.link_error(during, e)),
        }
    }

    /// Sends one request and returns its reply (same sequence number).
    fn request(
        &mut self,
        kind: u16,
        words: &[u32],
        timeout: Duration,
    ) -> Result<frame::Frame, PilError> {
        self.seq = self.seq.wrapping_add(1);
        let during = format!("the answer to request {} (kind {kind})", self.seq);
        let bytes = frame::encode(kind, self.seq, &frame::bytes_of(words))?;
        if let Err(e) = self.link.send(&bytes) {
            return Err(self.link_error(&during, e));
        }
        let reply = self.receive(&during, timeout)?;
        if reply.seq != self.seq {
            let e = PilError::Desync(format!(
                "reply numbered {}, request {}",
                reply.seq, self.seq
            ));
            return Err(self.link_error(&during, e));
        }
        Ok(reply)
    }
}

impl CoreEngine<f32> for PilCore {
    fn set_failures(
        &mut self,
        mask: FailureMask<MAX_AGENTS>,
    ) -> Result<FailureAnswer<f32>, BoxedError> {
        let reply = self.request(
            wire::KIND_SET_FAILURES,
            &[wire::mask_bits(&mask)],
            CYCLE_TIMEOUT,
        )?;
        match reply.kind {
            wire::KIND_HOVER => {
                let words = reply.words();
                let hover = wire::get_hover(&mut Reader::new(&words))
                    .ok_or_else(|| PilError::Desync("malformed hover classification".into()))?;
                self.failures = mask;
                Ok(Ok(hover))
            }
            wire::KIND_REFUSED => Ok(Err(reply.text(0))),
            k => Err(self.unexpected("a failure mask's answer", k).into()),
        }
    }

    fn failures(&self) -> FailureMask<MAX_AGENTS> {
        self.failures
    }

    fn set_landed(&mut self, landed: bool) -> Result<(), BoxedError> {
        let reply = self.request(wire::KIND_SET_LANDED, &[u32::from(landed)], CYCLE_TIMEOUT)?;
        match reply.kind {
            wire::KIND_LANDED if reply.words() == [u32::from(landed)] => Ok(()),
            k => Err(self.unexpected("the landed hold's answer", k).into()),
        }
    }

    fn step(
        &mut self,
        state: &RigidState<f32>,
        reference: &Reference<f32>,
    ) -> Result<CycleAnswer<f32>, BoxedError> {
        let mut words = [0u32; wire::INPUT_WORDS];
        wire::put_input(&mut Writer::new(&mut words), state, reference)
            .ok_or("input buffer too small")?;
        let reply = self.request(wire::KIND_STEP, &words, CYCLE_TIMEOUT)?;
        let words = reply.words();
        let mut r = Reader::new(&words);
        match reply.kind {
            wire::KIND_OUTPUT => {
                let out = wire::get_output(&mut r, self.n);
                let fault = wire::get_fault_answer(&mut r).filter(|_| r.remaining() == 0);
                let (Some(out), Some(fault)) = (out, fault) else {
                    return Err(PilError::Desync("malformed cycle output".into()).into());
                };
                self.answered(fault);
                Ok(Ok(out))
            }
            wire::KIND_SKIPPED => {
                let commands = wire::get_commands(&mut r, self.n);
                let fault = wire::get_fault_answer(&mut r);
                let (Some(commands), Some(fault)) = (commands, fault) else {
                    return Err(PilError::Desync("malformed skipped cycle".into()).into());
                };
                self.answered(fault);
                Ok(Err(SkippedCycle {
                    message: reply.text(4 * self.n + wire::FAULT_ANSWER_WORDS),
                    commands,
                }))
            }
            k => Err(self.unexpected("a cycle's answer", k).into()),
        }
    }

    fn fault_report(&self) -> Option<FaultReport<f32>> {
        self.fault.and_then(|f| f.report)
    }

    fn fault_masking(&self) -> Option<FaultMasking<f32>> {
        self.fault.and_then(|f| f.masking)
    }
}

impl PilCore {
    /// A cycle's fault answer: the detector's report and masking, and the mask in force (which
    /// the detector may have set on the target).
    fn answered(&mut self, fault: wire::FaultAnswer) {
        self.failures = fault.failures;
        self.fault = Some(fault);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn targets_parse_and_name_their_machine() {
        for t in PilTarget::ALL {
            assert_eq!(t.as_str().parse::<PilTarget>().unwrap(), t);
        }
        assert_eq!(PilTarget::CortexM4.label(), "cortex-m4 (qemu mps2-an386)");
        assert_eq!(PilTarget::CortexM7.machine(), "mps2-an500");
        let e = "cortex-m0".parse::<PilTarget>().unwrap_err();
        assert!(e.to_string().contains("cortex-m4, cortex-m7"), "{e}");
    }

    #[test]
    fn missing_firmware_names_the_build_command() {
        let only = candidates_with(Some("/nonexistent/tvmd-pil".into()));
        assert_eq!(only, [PathBuf::from("/nonexistent/tvmd-pil")]);
        let e = first_file(&only).unwrap_err();
        let m = e.to_string();
        assert!(m.contains("/nonexistent/tvmd-pil"), "{m}");
        let standard = candidates_with(None);
        assert!(standard
            .iter()
            .any(|p| p
                .ends_with("embedded/target-tests/target/thumbv7em-none-eabihf/release/tvmd-pil")));
        assert!(m.contains(BUILD_COMMAND) && m.contains(FIRMWARE_ENV), "{m}");
        assert!(PilError::QemuMissing
            .to_string()
            .contains("apt-get install"));
    }
}
