//! Starting PX4 SITL from a user's PX4 tree for one flight, headless, its outputs on
//! `simulator_mavlink`.
//!
//! The tree is used as built (`make px4_sitl_default`, or another SITL build such as
//! `px4_sitl_nolockstep`: [`Px4Launch::build`]); nothing in it is changed. The airframe
//! is PX4's own (`PX4_SYS_AUTOSTART`), and the flight's parameters (a params file of `param
//! set` lines) reach PX4 through its own hook: PX4's startup script sources `px4-rc.params`
//! from the `PATH` after the airframe and before the simulator starts, so the bridge writes
//! one into the flight's working directory and puts that directory first on PX4's `PATH`.
//! PX4 runs in that working directory (`-w`): its parameters, console output and ulog stay
//! with the flight.

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};

use crate::Px4Error;

/// PX4's default SITL build (lockstep): the build directory under the tree's `build/`.
pub const DEFAULT_BUILD: &str = "px4_sitl_default";

/// How to start PX4 for a flight.
#[derive(Clone, Debug, PartialEq)]
pub struct Px4Launch {
    /// The PX4 tree (`PX4_DIR`).
    pub tree: PathBuf,
    /// The SITL build to start, a directory under the tree's `build/` ([`DEFAULT_BUILD`];
    /// `px4_sitl_nolockstep` runs on the wall clock and needs the real-time bridge).
    pub build: String,
    /// The airframe (`PX4_SYS_AUTOSTART`).
    pub autostart: u32,
    /// A file of `param set NAME VALUE` lines applied after the airframe.
    pub params: Option<PathBuf>,
    /// The flight's working directory (made empty first).
    pub work_dir: PathBuf,
    /// PX4's instance (simulator port 4560 + instance, GCS port 18570 + instance).
    pub instance: u8,
    /// PX4's simulator: tvmd-sim over `simulator_mavlink`, or PX4's own SIH (for comparison).
    pub simulator: Simulator,
}

/// Which simulator PX4 flies on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Simulator {
    /// tvmd-sim over `simulator_mavlink` (`PX4_SIMULATOR=mavlink`).
    Tvmd,
    /// PX4's simulation-in-hardware quadcopter (`PX4_SIMULATOR=sihsim`, model `sihsim_quadx`),
    /// in real time.
    Sih,
}

/// The PX4 binary of `build` (a directory under `tree/build`, e.g. [`DEFAULT_BUILD`]) in
/// `tree`, or a clear error: no such directory, not a PX4 tree, not built, a build name that
/// is not one directory.
pub fn px4_binary(tree: &Path, build: &str) -> Result<PathBuf, Px4Error> {
    let refuse = |reason: String| Px4Error::Px4Tree {
        path: tree.display().to_string(),
        reason,
    };
    if !tree.is_dir() {
        return Err(refuse(
            "no such directory (set PX4_DIR to a PX4 source tree, e.g. a clone of \
             github.com/PX4/PX4-Autopilot or the authors' TVMD-PX4)"
                .into(),
        ));
    }
    if !tree.join("ROMFS/px4fmu_common/init.d-posix/rcS").is_file() {
        return Err(refuse(
            "not a PX4 source tree (no ROMFS/px4fmu_common/init.d-posix/rcS)".into(),
        ));
    }
    let single = Path::new(build).components().count() == 1
        && !matches!(build, "" | "." | "..")
        && !build.contains('/');
    if !single {
        return Err(refuse(format!(
            "`{build}` is not a build name (a directory under build/, e.g. {DEFAULT_BUILD})"
        )));
    }
    let relative = format!("build/{build}/bin/px4");
    let binary = tree.join(&relative);
    if !binary.is_file() {
        return Err(refuse(format!(
            "PX4 SITL is not built ({relative} is missing): run `make {build}` in the tree \
             (scripts/px4.sh builds {DEFAULT_BUILD})"
        )));
    }
    Ok(binary)
}

/// A running PX4, stopped when dropped.
pub struct Px4Process {
    child: Child,
    work_dir: PathBuf,
}

impl Px4Process {
    /// Starts PX4 as `launch` says, its console output into `work_dir/px4-console.txt`.
    pub fn start(launch: &Px4Launch) -> Result<Self, Px4Error> {
        let binary = px4_binary(&launch.tree, &launch.build)?;
        let io = |what: &str| {
            let what = format!("PX4 start: {what}");
            move |source| Px4Error::Link { what, source }
        };
        if launch.work_dir.exists() {
            std::fs::remove_dir_all(&launch.work_dir).map_err(io("clear the working directory"))?;
        }
        std::fs::create_dir_all(&launch.work_dir).map_err(io("make the working directory"))?;
        // Absolute paths: PX4 changes into its working directory, where a relative hook
        // directory on its PATH (the flight's parameters) or data path would not resolve.
        let work = &std::fs::canonicalize(&launch.work_dir)
            .map_err(io("resolve the working directory"))?;
        let tree = std::fs::canonicalize(&launch.tree).map_err(io("resolve the PX4 tree"))?;
        let hooks = work.join("hooks");
        std::fs::create_dir_all(&hooks).map_err(io("make the hook directory"))?;
        let mut params = String::from("#!/bin/sh\n# The flight's parameters (tvmd-sim px4).\n");
        if let Some(file) = &launch.params {
            let text = std::fs::read_to_string(file).map_err(|e| Px4Error::FlightFile {
                path: file.display().to_string(),
                reason: e.to_string(),
            })?;
            params.push_str(&text);
        }
        std::fs::write(hooks.join("px4-rc.params"), params).map_err(io("write px4-rc.params"))?;
        let console = std::fs::File::create(work.join("px4-console.txt"))
            .map_err(io("create px4-console.txt"))?;
        let path = std::env::var("PATH").unwrap_or_default();
        let child = Command::new(&binary)
            .arg("-d")
            .arg("-i")
            .arg(launch.instance.to_string())
            .arg("-w")
            .arg(work.join("rootfs"))
            .arg(tree.join("build").join(&launch.build).join("etc"))
            .env("PATH", format!("{}:{path}", hooks.display()))
            .env("PX4_SYS_AUTOSTART", launch.autostart.to_string())
            // An external simulator on simulator_mavlink: neither SIH nor Gazebo.
            .env(
                "PX4_SIMULATOR",
                match launch.simulator {
                    Simulator::Tvmd => "mavlink",
                    Simulator::Sih => "sihsim",
                },
            )
            .env(
                "PX4_SIM_MODEL",
                match launch.simulator {
                    Simulator::Tvmd => "tvmd",
                    Simulator::Sih => "sihsim_quadx",
                },
            )
            .env("HEADLESS", "1")
            .stdin(Stdio::null())
            .stdout(console.try_clone().map_err(io("console"))?)
            .stderr(console)
            .spawn()
            .map_err(io(&format!("run {}", binary.display())))?;
        Ok(Self {
            child,
            work_dir: work.to_path_buf(),
        })
    }

    /// `Err` if PX4 has exited (its status named).
    pub fn check_running(&mut self) -> Result<(), Px4Error> {
        match self.child.try_wait() {
            Ok(None) => Ok(()),
            Ok(Some(status)) => Err(Px4Error::Px4Tree {
                path: self.work_dir.display().to_string(),
                reason: format!(
                    "PX4 exited ({status}) before connecting; see px4-console.txt there"
                ),
            }),
            Err(source) => Err(Px4Error::Link {
                what: "PX4 status".into(),
                source,
            }),
        }
    }

    /// Stops PX4 (SIGTERM, which PX4 takes as a shutdown and closes its ulog; SIGKILL after
    /// 5 s) and returns its newest ulog.
    pub fn stop(mut self) -> Option<PathBuf> {
        let _ = Command::new("kill")
            .arg("-TERM")
            .arg(self.child.id().to_string())
            .status();
        let start = std::time::Instant::now();
        while matches!(self.child.try_wait(), Ok(None))
            && start.elapsed() < std::time::Duration::from_secs(5)
        {
            std::thread::sleep(std::time::Duration::from_millis(20));
        }
        let _ = self.child.kill();
        let _ = self.child.wait();
        newest_ulog(&self.work_dir.join("rootfs/log"))
    }
}

impl Drop for Px4Process {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// The newest `.ulg` under `dir` (PX4 writes `log/YYYY-MM-DD/HH_MM_SS.ulg`).
pub fn newest_ulog(dir: &Path) -> Option<PathBuf> {
    let mut best: Option<(std::time::SystemTime, PathBuf)> = None;
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for entry in std::fs::read_dir(&d).ok()?.flatten() {
            let p = entry.path();
            if p.is_dir() {
                stack.push(p);
            } else if p.extension().is_some_and(|e| e == "ulg") {
                let m = entry.metadata().and_then(|m| m.modified()).ok()?;
                if best.as_ref().is_none_or(|(t, _)| m > *t) {
                    best = Some((m, p));
                }
            }
        }
    }
    best.map(|(_, p)| p)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_missing_tree_and_an_unbuilt_tree_are_named() {
        let e = px4_binary(Path::new("/nonexistent/px4"), DEFAULT_BUILD)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("/nonexistent/px4") && e.contains("no such directory"),
            "{e}"
        );
        let dir = std::env::temp_dir().join(format!("tvmd-px4-tree-{}", std::process::id()));
        std::fs::create_dir_all(dir.join("ROMFS/px4fmu_common/init.d-posix")).unwrap();
        let e = px4_binary(&dir, DEFAULT_BUILD).unwrap_err().to_string();
        assert!(e.contains("not a PX4 source tree"), "{e}");
        std::fs::write(dir.join("ROMFS/px4fmu_common/init.d-posix/rcS"), "").unwrap();
        let e = px4_binary(&dir, DEFAULT_BUILD).unwrap_err().to_string();
        assert!(
            e.contains("not built") && e.contains("make px4_sitl_default"),
            "{e}"
        );
        let e = px4_binary(&dir, "px4_sitl_nolockstep")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("build/px4_sitl_nolockstep/bin/px4 is missing")
                && e.contains("make px4_sitl_nolockstep"),
            "{e}"
        );
        for bad in ["", "..", "../elsewhere", "a/b"] {
            let e = px4_binary(&dir, bad).unwrap_err().to_string();
            assert!(e.contains("is not a build name"), "{bad}: {e}");
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
