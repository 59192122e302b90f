//! Run-time overrides of a scenario (the command line's `--relaxation` / `--allocator` /
//! `--precision` / `--team` / `--law` / `--detect` / `--reports`, the Python keywords `relaxation=` / `allocator=` /
//! `precision=` / `law=`), applied with validation.

use super::{AgentReports, FaultDetectionConfig, LawConfig, NullSpaceConfig, Precision, Scenario};
use crate::ScenarioError;

/// Fields of a scenario replaced at run time; `None` keeps the scenario's value.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Overrides {
    /// Planner relaxation `s` in `(0, 1]`.
    pub relaxation: Option<f64>,
    /// Allocator name (one of [`super::ALLOCATOR_NAMES`]).
    pub allocator: Option<String>,
    /// The controller's float type (`controller_precision`).
    pub precision: Option<Precision>,
    /// A null-space stage after the allocator (`null_space`).
    pub null_space: Option<NullSpaceConfig>,
    /// A catalogue team (`team.preset`, e.g. `"a6-inc"`), replacing the scenario's team.
    pub team: Option<String>,
    /// The control law (`[law]`), e.g. [`LawConfig::paper`] to fly a family with the paper's
    /// law.
    pub law: Option<LawConfig>,
    /// Agent fault detection (`[fault_detection]`), e.g. the recommended detector with the
    /// `"mask"` response.
    pub fault_detection: Option<FaultDetectionConfig>,
    /// The agents' own reports (`[reports]`), e.g. the simulator's defaults with a dead ESC
    /// that reports zero speed.
    pub reports: Option<AgentReports>,
}

impl Overrides {
    /// True if nothing is overridden.
    pub fn is_empty(&self) -> bool {
        self.relaxation.is_none()
            && self.allocator.is_none()
            && self.precision.is_none()
            && self.null_space.is_none()
            && self.team.is_none()
            && self.law.is_none()
            && self.fault_detection.is_none()
            && self.reports.is_none()
    }

    /// Applies the overrides to `scenario` and validates the result; errors name the field.
    pub fn apply(&self, scenario: &mut Scenario) -> Result<(), ScenarioError> {
        if let Some(s) = self.relaxation {
            scenario.relaxation = s;
        }
        if let Some(a) = &self.allocator {
            scenario.allocator.clone_from(a);
        }
        if let Some(p) = self.precision {
            scenario.controller_precision = p;
        }
        if let Some(n) = self.null_space {
            scenario.null_space = Some(n);
        }
        if let Some(law) = self.law {
            scenario.law = law;
        }
        if let Some(detection) = self.fault_detection {
            scenario.fault_detection = Some(detection);
        }
        if let Some(reports) = &self.reports {
            scenario.reports = Some(reports.clone());
        }
        if let Some(team) = &self.team {
            scenario.team.preset = Some(team.clone());
            scenario.team.agents = None;
        }
        scenario.validate()
    }
}

impl Scenario {
    /// This scenario with `overrides` applied, validated.
    pub fn with_overrides(mut self, overrides: &Overrides) -> Result<Self, ScenarioError> {
        overrides.apply(&mut self)?;
        Ok(self)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn overrides_replace_and_validate() {
        let o = Overrides {
            relaxation: Some(1.0),
            allocator: Some("pseudo-inverse".into()),
            precision: Some(Precision::F32),
            null_space: Some("margin".parse().unwrap()),
            team: Some("a6-inc".into()),
            law: Some(LawConfig::paper()),
            fault_detection: None,
            reports: Some(AgentReports {
                rate: 50.0,
                ..AgentReports::default()
            }),
        };
        assert!(!o.is_empty() && Overrides::default().is_empty());
        let s = Scenario::default().with_overrides(&o).unwrap();
        assert_eq!(s.relaxation, 1.0);
        assert_eq!(s.allocator, "pseudo-inverse");
        assert_eq!(s.controller_precision, Precision::F32);
        assert_eq!(s.team_body().unwrap().len(), 6);
        assert_eq!(s.law, LawConfig::paper());
        assert_eq!(s.reports.as_ref().map(|r| r.rate), Some(50.0));
        assert_ne!(Scenario::default().law, LawConfig::paper());
        let bad = Overrides {
            team: Some("a99".into()),
            ..Overrides::default()
        };
        let e = Scenario::default().with_overrides(&bad).unwrap_err();
        assert!(e.to_string().contains("team.preset"), "{e}");
        assert_eq!(
            s.null_space.map(|n| n.to_string()).as_deref(),
            Some("margin")
        );
        assert_eq!(
            Scenario::default()
                .with_overrides(&Overrides::default())
                .unwrap(),
            Scenario::default()
        );
        let bad = Overrides {
            relaxation: Some(1.5),
            ..Overrides::default()
        };
        let e = Scenario::default().with_overrides(&bad).unwrap_err();
        assert!(
            matches!(&e, ScenarioError::InvalidScenario { field, .. } if field == "relaxation"),
            "{e}"
        );
        let bad = Overrides {
            allocator: Some("magic".into()),
            ..Overrides::default()
        };
        let e = Scenario::default().with_overrides(&bad).unwrap_err();
        assert!(
            matches!(&e, ScenarioError::InvalidScenario { field, .. } if field == "allocator"),
            "{e}"
        );
        let bad = Overrides {
            reports: Some(AgentReports {
                latency: -1.0,
                ..AgentReports::default()
            }),
            ..Overrides::default()
        };
        let e = Scenario::default().with_overrides(&bad).unwrap_err();
        assert!(e.to_string().contains("reports.latency"), "{e}");
    }
}
