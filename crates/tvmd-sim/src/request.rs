//! One run as the command line (`tvmd-sim run`, `sweep`) and Python (`tvmd.sim.run`,
//! `run_many`, `relaxation_sweep`) ask for it: [`RunRequest`], with the one parser of its
//! string-valued options ([`RunRequest::parse_precision`], [`RunRequest::parse_pil`],
//! [`RunRequest::parse_null_space`]; errors name the option) and the one
//! [`RunRequest::spec`] that loads the scenario, applies the overrides, validates the result
//! and checks the log against the scenario file it read.

use std::path::{Path, PathBuf};

use tvmd_scenario::{
    AgentReports, DeadEsc, FaultDetectionConfig, FaultResponseConfig, LawConfig, NullSpaceConfig,
    Overrides, Precision, Scenario,
};

use crate::runner::RunSpec;
use crate::sim::SampleRetention;
use crate::SimError;
use tvmd_pil::PilTarget;

/// The scenario of a run request.
#[derive(Clone, Debug, Default, PartialEq)]
pub enum ScenarioSource {
    /// The default scenario, [`RunRequest::DEFAULT_SCENARIO`].
    #[default]
    Default,
    /// A built-in name or a TOML file, by [`Scenario::load`]'s rule (the command line's and
    /// Python's `str`).
    NameOrFile(String),
    /// A TOML file (Python's `os.PathLike`).
    File(PathBuf),
    /// TOML text (Python's `toml=`).
    Toml(String),
}

impl ScenarioSource {
    /// The file this source reads, if it reads one (an input no output may overwrite).
    pub fn file(&self) -> Option<&Path> {
        match self {
            Self::File(path) => Some(path),
            Self::NameOrFile(s) => {
                let path = Path::new(s);
                (s.ends_with(".toml") || path.is_file()).then_some(path)
            }
            Self::Default | Self::Toml(_) => None,
        }
    }

    /// Loads the scenario (not yet overridden).
    pub fn load(&self) -> Result<Scenario, SimError> {
        Ok(match self {
            Self::Default => Scenario::builtin(RunRequest::DEFAULT_SCENARIO)?,
            Self::NameOrFile(s) => Scenario::load(s)?,
            Self::File(path) => Scenario::from_file(path)?,
            Self::Toml(text) => Scenario::from_toml_str(text)?,
        })
    }
}

/// One run as asked for: the scenario, its overrides, where the controller runs, the log and
/// the samples to keep. Build it from typed values or from strings (the parsers below), then
/// [`RunRequest::spec`].
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RunRequest {
    /// The scenario.
    pub scenario: ScenarioSource,
    /// Override of the relaxation `s`.
    pub relaxation: Option<f64>,
    /// Override of the allocator (a name of `AnyAllocator::NAMES`).
    pub allocator: Option<String>,
    /// Override of the null-space stage.
    pub null_space: Option<NullSpaceConfig>,
    /// Override of the team (a catalogue preset).
    pub team: Option<String>,
    /// Override of the control law (`[law]`).
    pub law: Option<LawConfig>,
    /// Override of the fault detection (`[fault_detection]`).
    pub fault_detection: Option<FaultDetectionConfig>,
    /// Override of the agents' reports (`[reports]`).
    pub reports: Option<AgentReports>,
    /// Override of the controller precision.
    pub precision: Option<Precision>,
    /// The processor-in-the-loop target, or `None` for the host.
    pub pil: Option<PilTarget>,
    /// The MCAP log to write.
    pub log: Option<PathBuf>,
    /// The samples the result keeps.
    pub samples: SampleRetention,
}

impl RunRequest {
    /// The scenario of a request that names none.
    pub const DEFAULT_SCENARIO: &'static str = "paper-tilt";

    /// The option `precision` (`f64`, `f32`); the error names `controller_precision`.
    pub fn parse_precision(text: &str) -> Result<Precision, SimError> {
        Ok(text.parse::<Precision>()?)
    }

    /// The option `law` (`paper`, `offset-free`); the error names `law`.
    pub fn parse_law(text: &str) -> Result<LawConfig, SimError> {
        text.parse::<LawConfig>().map_err(|e| invalid("law", e))
    }

    /// The option `detect` (`report`, `mask`): the recommended fault detector with that
    /// response; the error names `fault_detection`.
    pub fn parse_fault_detection(text: &str) -> Result<FaultDetectionConfig, SimError> {
        let response = match text {
            "report" => FaultResponseConfig::Report,
            "mask" => FaultResponseConfig::Mask,
            other => {
                return Err(invalid(
                    "fault_detection",
                    format!("unknown response `{other}` (known: report, mask)"),
                ))
            }
        };
        Ok(FaultDetectionConfig::with_response(response))
    }

    /// The option `reports` (`silent`, `zero`): the agents' reports at the simulator's
    /// defaults ([`AgentReports::default`]: 100 Hz, 20 ms latency, 0.05 N and 5 mrad of
    /// noise), a dead ESC reporting nothing or zero speed; the error names `reports`.
    pub fn parse_reports(text: &str) -> Result<AgentReports, SimError> {
        let dead_esc = match text {
            "silent" => DeadEsc::Silent,
            "zero" => DeadEsc::Zero,
            other => {
                return Err(invalid(
                    "reports",
                    format!("unknown dead ESC `{other}` (known: silent, zero)"),
                ))
            }
        };
        Ok(AgentReports {
            dead_esc,
            ..AgentReports::default()
        })
    }

    /// The option `pil` (`cortex-m4`, `cortex-m7`); the error names `pil`.
    pub fn parse_pil(text: &str) -> Result<PilTarget, SimError> {
        text.parse::<PilTarget>()
            .map_err(|e| invalid("pil", e.to_string()))
    }

    /// The option `null_space` (`margin`, `inward-tilt=<rad>`), parsed and validated; the error
    /// names `null_space` (or its field).
    pub fn parse_null_space(text: &str) -> Result<NullSpaceConfig, SimError> {
        let config: NullSpaceConfig = text.parse().map_err(|e| invalid("null_space", e))?;
        config.validate()?;
        Ok(config)
    }

    /// Parses each given string option (`precision`, `pil`, `null_space`) into this request,
    /// the first error naming its option.
    pub fn with_strings(
        mut self,
        precision: Option<&str>,
        pil: Option<&str>,
        null_space: Option<&str>,
    ) -> Result<Self, SimError> {
        if let Some(p) = precision {
            self.precision = Some(Self::parse_precision(p)?);
        }
        if let Some(p) = pil {
            self.pil = Some(Self::parse_pil(p)?);
        }
        if let Some(n) = null_space {
            self.null_space = Some(Self::parse_null_space(n)?);
        }
        Ok(self)
    }

    /// The overrides of this request.
    pub fn overrides(&self) -> Overrides {
        Overrides {
            relaxation: self.relaxation,
            allocator: self.allocator.clone(),
            precision: self.precision,
            null_space: self.null_space,
            team: self.team.clone(),
            law: self.law,
            fault_detection: self.fault_detection,
            reports: self.reports.clone(),
        }
    }

    /// The scenario file this request reads, if any.
    pub fn input(&self) -> Option<&Path> {
        self.scenario.file()
    }

    /// Loads the scenario, applies the overrides, validates the result for the target
    /// ([`RunSpec::on_target`]) and checks the log ([`RunRequest::check_log`]). Nothing is
    /// written but the log's directory.
    pub fn spec(&self) -> Result<RunSpec, SimError> {
        let spec = self.flight()?;
        self.check_log()?;
        Ok(spec)
    }

    /// [`RunRequest::spec`] without the log check (for a caller that checks it itself, naming
    /// the run in a batch).
    pub fn flight(&self) -> Result<RunSpec, SimError> {
        let scenario = self.scenario.load()?.with_overrides(&self.overrides())?;
        let mut spec = RunSpec::on_target(scenario, self.log.clone(), self.pil, self.precision)?;
        spec.samples = self.samples;
        Ok(spec)
    }

    /// Checks the log before any work ([`tvmd_log::paths`]): it names a file, not a directory,
    /// in a writable directory (made if missing), and is not the scenario file this request
    /// reads.
    pub fn check_log(&self) -> Result<(), SimError> {
        let Some(log) = &self.log else {
            return Ok(());
        };
        tvmd_log::paths::check_output(log, "the log", "write the MCAP log")?;
        let inputs: Vec<(String, &Path)> = self
            .input()
            .map(|p| ("scenario file".to_string(), p))
            .into_iter()
            .collect();
        tvmd_log::paths::check_outputs(&[("the log".to_string(), log)], &inputs)?;
        Ok(())
    }
}

fn invalid(name: &str, reason: impl Into<String>) -> SimError {
    SimError::InvalidArgument {
        name: name.into(),
        reason: reason.into(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn strings_parse_once_and_errors_name_the_option() {
        let r = RunRequest::default()
            .with_strings(Some("f32"), None, Some("inward-tilt=0.1"))
            .unwrap();
        assert_eq!(r.precision, Some(Precision::F32));
        assert!(r.null_space.is_some_and(|n| n.tilt == Some(0.1)));
        let e = RunRequest::parse_precision("f16").unwrap_err().to_string();
        assert!(
            e.contains("controller_precision") && e.contains("f16"),
            "{e}"
        );
        let r = RunRequest::parse_reports("zero").unwrap();
        assert_eq!(r.dead_esc, DeadEsc::Zero);
        assert_eq!(r.rate, AgentReports::default().rate);
        let e = RunRequest::parse_reports("loud").unwrap_err().to_string();
        assert!(e.contains("`reports`") && e.contains("loud"), "{e}");
        let e = RunRequest::parse_pil("cortex-z9").unwrap_err().to_string();
        assert!(e.contains("`pil`"), "{e}");
        let e = RunRequest::parse_null_space("nope")
            .unwrap_err()
            .to_string();
        assert!(e.contains("null_space"), "{e}");
    }

    #[test]
    fn the_spec_applies_overrides_and_refuses_the_scenario_as_log() {
        let r = RunRequest {
            scenario: ScenarioSource::Toml("duration = 0.2\n".into()),
            relaxation: Some(0.75),
            samples: SampleRetention::None,
            ..RunRequest::default()
        };
        let spec = r.spec().unwrap();
        assert_eq!(spec.scenario.relaxation, 0.75);
        assert_eq!(spec.samples, SampleRetention::None);
        assert_eq!(
            RunRequest::default().spec().unwrap().scenario.name,
            "paper-tilt"
        );
        let dir = std::env::temp_dir().join(format!("tvmd-request-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let file = dir.join("s.toml");
        std::fs::write(&file, "duration = 0.5\n").unwrap();
        for scenario in [
            ScenarioSource::File(file.clone()),
            ScenarioSource::NameOrFile(file.display().to_string()),
        ] {
            let r = RunRequest {
                scenario,
                log: Some(dir.join(".").join("s.toml")),
                ..RunRequest::default()
            };
            let e = r.spec().unwrap_err().to_string();
            assert!(e.contains("scenario file"), "{e}");
        }
        assert_eq!(std::fs::read_to_string(&file).unwrap(), "duration = 0.5\n");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
