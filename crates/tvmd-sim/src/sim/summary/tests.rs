use super::*;
use nalgebra::Vector3;

/// A sample at `t` with position and `V_x` `x` (shared with the sample store's tests).
pub(crate) fn sample(t: f64, x: f64, e_f: Option<f64>) -> Sample {
    Sample {
        t,
        position: [x, 0.0, 1.0],
        velocity: [0.0; 3],
        omega: [0.0; 3],
        rotation: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
        reference_position: [0.0, 0.0, 1.0],
        roll_pitch_yaw: [0.0; 3],
        reference_roll_pitch_yaw: [0.0; 3],
        reference_roll: 0.0,
        planned_roll: Some(-x),
        planned_roll_pitch_yaw: None,
        attitude_error: None,
        reference_attitude_error: 0.0,
        theta: None,
        e_f,
        e_tau: None,
        thrust_efficiency: None,
        saturated_agents: None,
        null_space_margins: None,
        v_x: Some(x),
        v_r: None,
        cycle_error: false,
        hover: None,
        fault: None,
        commands: Vec::new(),
        actual: Vec::new(),
        failed: Vec::new(),
    }
}

#[test]
fn sample_at_is_the_nearest_within_half_a_spacing() {
    let samples: Vec<Sample> = (0..5)
        .map(|k| sample(k as f64 * 0.01, k as f64, None))
        .collect();
    assert_eq!(sample_at(&samples, 0.021).map(|s| s.t), Some(0.02));
    assert_eq!(sample_at(&samples, 0.025 - 1e-6).map(|s| s.t), Some(0.02));
    assert_eq!(sample_at(&samples, 0.0449).map(|s| s.t), Some(0.04));
    assert!(sample_at(&samples, 0.0451).is_none());
    assert!(sample_at(&[], 0.0).is_none());
    assert_eq!(
        sample_at(&samples, 0.03).map(Sample::horizontal_error),
        Some(3.0)
    );
}

#[test]
fn summary_and_paper_metrics_share_the_rules() {
    let samples = vec![
        sample(0.0, 0.5, Some(0.0)),
        sample(4.0, 0.2, Some(2e-6)),
        sample(8.0, 0.1, Some(3e-6)),
        sample(12.0, 0.3, Some(3e-6)),
    ];
    let scenario = Scenario {
        duration: 16.0,
        ..Scenario::default()
    };
    let totals = RunTotals {
        time: 16.0,
        final_state: PlantState::at_rest(Vector3::new(0.3, 0.0, 1.0)),
        mass: 2.0,
        controller_calls: 4,
        physics_steps: 16,
        wall_time: 0.0,
        interrupted: false,
    };
    let summary = RunSummary::new(&scenario, &samples, &totals);
    let paper = PaperMetrics::new(&scenario, &samples);
    assert_eq!(summary.horizontal_error_at_4s, Some(0.2));
    assert_eq!(summary.horizontal_error_at_12s, Some(0.3));
    assert_eq!(paper.horizontal_error_at_4s, summary.horizontal_error_at_4s);
    assert_eq!(
        paper.horizontal_error_at_12s,
        summary.horizontal_error_at_12s
    );
    assert_eq!(summary.max_planned_roll, Some(0.5));
    assert_eq!(paper.max_planned_roll, summary.max_planned_roll);
    // The first of equal maxima.
    assert_eq!(
        (summary.max_e_f, summary.max_e_f_time),
        (Some(3e-6), Some(8.0))
    );
    assert_eq!(paper.max_e_f, Some((3e-6, 8.0)));
    assert_eq!(paper.e_f_onset, Some(4.0));
    assert_eq!(paper.e_f_visible, E_F_VISIBLE);
    // In f32 a few uN are round-off, not a lost force.
    let f32_scenario = Scenario {
        controller_precision: Precision::F32,
        ..scenario.clone()
    };
    let f32_paper = PaperMetrics::new(&f32_scenario, &samples);
    let weight = 2.8 * tvmd_plant::GRAVITY;
    assert_eq!(f32_paper.e_f_visible, e_f_visible(Precision::F32, weight));
    assert!((f32_paper.e_f_visible - 16.0 * 1.1920929e-7 * weight).abs() < 1e-12);
    assert_eq!(f32_paper.e_f_onset, None);
    assert_eq!(e_f_visible(Precision::F64, weight), E_F_VISIBLE);
    assert_eq!(summary.max_position_error_after_4s, 0.3);
    assert_eq!(paper.max_position_error_6_to_12s, Some(0.3));
    assert_eq!(summary.real_time_factor, f64::INFINITY);
    let rise = paper.max_v_x_rise.unwrap();
    assert_eq!((rise.from, rise.to, rise.rise), (8.0, 12.0, 0.3 - 0.1));
}
