//! `relaxation = "certified"`: the AFS atlas's `s*` of a scenario's team.

use super::{LimitsConfig, Scenario};
use tvmd_plant::GRAVITY;

use crate::ScenarioError;
use tvmd_core::presets::Preset;

impl Scenario {
    /// The certified relaxation `s*` of the scenario's team (`relaxation = "certified"`): the
    /// AFS atlas's value for a catalogue preset with the paper's limits
    /// (`tvmd_core::presets::Preset::certified_relaxation`), the smallest over the
    /// nominal team and each agent a `[[failures]]` entry removes. Errors for explicit agents,
    /// other limits, or a degraded team without a certified value.
    pub fn certified_relaxation(&self) -> Result<f64, ScenarioError> {
        let invalid = |reason: String| ScenarioError::InvalidScenario {
            field: "relaxation".into(),
            reason,
        };
        if self.team.agents.is_some() {
            return Err(invalid(
                "\"certified\" needs a catalogue `team.preset`; for explicit agents compute s* \
                 with `tvmd-sim afs` and give it as a number"
                    .into(),
            ));
        }
        let name = self.team.preset.as_deref().unwrap_or("a4-inc");
        let preset =
            Preset::from_name(name).ok_or_else(|| invalid(format!("unknown preset `{name}`")))?;
        let paper = LimitsConfig::default();
        let paper_thrust = 2.0 * self.team.agent_mass * GRAVITY;
        let thrust_is_paper = self
            .limits
            .max_thrust
            .is_none_or(|t| (t - paper_thrust).abs() <= 1e-9 * paper_thrust);
        if self.limits.sigma_x != paper.sigma_x
            || self.limits.sigma_y != paper.sigma_y
            || !thrust_is_paper
        {
            return Err(invalid(
                "\"certified\" values are for the paper's limits (sigma_x = pi/6, sigma_y = pi/4, \
                 sigma_Tf = 2 m_i g); compute s* for these limits with `tvmd-sim afs`"
                    .into(),
            ));
        }
        let mut masks: Vec<Option<usize>> = vec![None];
        masks.extend(self.failures.iter().map(|f| Some(f.agent)));
        masks
            .into_iter()
            .map(|failed| {
                preset
                    .certified_relaxation::<f64>(failed)
                    .map(|s| s.get())
                    .ok_or_else(|| {
                        invalid(format!(
                            "no certified s* for {name}{}",
                            failed.map_or(String::new(), |i| format!(" without agent {i}"))
                        ))
                    })
            })
            .try_fold(1.0_f64, |lo, s| s.map(|s| lo.min(s)))
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    #[test]
    fn certified_relaxation_comes_from_the_core_table() {
        let s = Scenario::from_toml_str("relaxation = \"certified\"\n").unwrap();
        let want = Preset::A4Inc
            .certified_relaxation::<f64>(None)
            .unwrap()
            .get();
        assert_eq!(s.relaxation, want);
        let builtin = Scenario::builtin("relaxation-certified").unwrap();
        assert_eq!(builtin.relaxation, want);
        // Another preset, and the minimum over a scheduled failure.
        let text = "relaxation = \"certified\"\n[team]\npreset = \"a6-inc\"\n\
                    [[failures]]\nagent = 0\ntime = 5.0\nkind = \"no-thrust\"\n";
        let s = Scenario::from_toml_str(text).unwrap();
        let nominal = Preset::A6Inc
            .certified_relaxation::<f64>(None)
            .unwrap()
            .get();
        let degraded = Preset::A6Inc
            .certified_relaxation::<f64>(Some(0))
            .unwrap()
            .get();
        assert_eq!(s.relaxation, nominal.min(degraded));
    }

    #[test]
    fn certified_relaxation_is_refused_where_the_table_does_not_apply() {
        let other_limits = "relaxation = \"certified\"\n[limits]\nsigma_y = 0.5\n";
        let e = Scenario::from_toml_str(other_limits)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("relaxation") && e.contains("paper's limits"),
            "{e}"
        );
        let agents = "relaxation = \"certified\"\n[team]\nagents = [\n\
            { position = [0.5, 0.0, 0.0], mass = 0.7, quarter_turns = 0 },\n\
            { position = [0.0, 0.5, 0.0], mass = 0.7, quarter_turns = 1 },\n\
            { position = [-0.5, 0.0, 0.0], mass = 0.7, quarter_turns = 0 },\n\
            { position = [0.0, -0.5, 0.0], mass = 0.7, quarter_turns = 1 }]\n";
        let e = Scenario::from_toml_str(agents).unwrap_err().to_string();
        assert!(e.contains("catalogue"), "{e}");
        // Any other string is still a parse error naming the field.
        let e = Scenario::from_toml_str("relaxation = \"best\"\n")
            .unwrap_err()
            .to_string();
        assert!(e.contains("relaxation"), "{e}");
    }
}
