//! The QEMU process of a PIL flight: `qemu-system-arm` running the PIL firmware, its first
//! serial port (the CMSDK UART0 of the mps2 boards) on QEMU's stdin/stdout, stderr kept for
//! error messages. Dropping the link kills the process.

use std::io::{Read, Write};
use std::path::Path;
use std::process::{Child, ChildStdin, Command, Stdio};
use std::sync::mpsc::channel;
use std::sync::{Arc, Mutex};
use std::time::Instant;

use crate::error::PilError;
use crate::frame::{self, ByteSource, ChannelSource, Frame};

/// The emulator binary.
pub const QEMU: &str = "qemu-system-arm";

/// A running QEMU with the PIL firmware.
pub struct QemuLink {
    child: Child,
    stdin: ChildStdin,
    source: ChannelSource,
    stderr: Arc<Mutex<Vec<u8>>>,
}

impl std::fmt::Debug for QemuLink {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("QemuLink")
            .field("pid", &self.child.id())
            .finish_non_exhaustive()
    }
}

impl QemuLink {
    /// Starts `qemu-system-arm -machine <machine>` on the firmware `elf`.
    pub fn spawn(machine: &str, elf: &Path) -> Result<Self, PilError> {
        let mut child = Command::new(QEMU)
            .args(["-machine", machine, "-display", "none", "-monitor", "none"])
            .args(["-parallel", "none", "-serial", "stdio"])
            .args(["-semihosting-config", "enable=on,target=native"])
            .arg("-kernel")
            .arg(elf)
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .map_err(|e| match e.kind() {
                std::io::ErrorKind::NotFound => PilError::QemuMissing,
                _ => PilError::Io(e),
            })?;
        let (Some(stdin), Some(mut stdout), Some(mut err)) =
            (child.stdin.take(), child.stdout.take(), child.stderr.take())
        else {
            let _ = child.kill();
            let _ = child.wait();
            return Err(PilError::Io(std::io::Error::other(
                "QEMU's pipes are missing",
            )));
        };
        let (tx, rx) = channel();
        std::thread::spawn(move || {
            let mut buf = [0u8; 4096];
            // Ends when QEMU closes its stdout (exit) or the link is dropped.
            while let Ok(k @ 1..) = stdout.read(&mut buf) {
                if tx.send(buf[..k].to_vec()).is_err() {
                    break;
                }
            }
        });
        let stderr = Arc::new(Mutex::new(Vec::new()));
        let sink = Arc::clone(&stderr);
        std::thread::spawn(move || {
            let mut buf = Vec::new();
            let _ = err.read_to_end(&mut buf);
            if let Ok(mut s) = sink.lock() {
                s.extend(buf);
            }
        });
        Ok(Self {
            child,
            stdin,
            source: ChannelSource::new(rx),
            stderr,
        })
    }

    /// Sends one frame.
    pub fn send(&mut self, bytes: &[u8]) -> Result<(), PilError> {
        self.stdin
            .write_all(bytes)
            .and_then(|()| self.stdin.flush())
            .map_err(|_| PilError::Closed)
    }

    /// Receives one frame before `deadline`.
    pub fn receive(&mut self, deadline: Instant) -> Result<Frame, PilError> {
        frame::read_frame(&mut self.source, deadline)
    }

    /// What QEMU wrote to stderr so far and, if it has exited, its status.
    pub fn diagnostics(&mut self) -> String {
        let status = match self.child.try_wait() {
            Ok(Some(s)) => format!("QEMU exited ({s})"),
            _ => "QEMU still running".to_string(),
        };
        // Give the stderr thread a moment to collect the last lines of an exited QEMU.
        std::thread::sleep(std::time::Duration::from_millis(50));
        let text = self
            .stderr
            .lock()
            .map(|s| String::from_utf8_lossy(&s).trim().to_string())
            .unwrap_or_default();
        if text.is_empty() {
            status
        } else {
            format!("{status}; stderr: {text}")
        }
    }
}

impl ByteSource for QemuLink {
    fn read_exact(&mut self, buf: &mut [u8], deadline: Instant) -> Result<(), PilError> {
        self.source.read_exact(buf, deadline)
    }
}

impl Drop for QemuLink {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}
