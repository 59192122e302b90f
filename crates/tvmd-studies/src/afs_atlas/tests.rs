#![allow(clippy::unwrap_used, clippy::indexing_slicing)]
//! The exact-set computation against brute-force sampling.

use super::*;
use nalgebra::{Matrix4, Vector3, Vector4, Vector6};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use tvmd_core::presets::Preset;
use tvmd_core::{FailureMask, GimbalCommand, Relaxation, TeamConfig};

fn team(preset: Preset) -> TeamConfig<f64, 16> {
    preset.team().unwrap()
}

fn model(preset: Preset, failed: &[usize]) -> AtlasModel {
    let mask = FailureMask::with_failed(failed).unwrap();
    AtlasModel::new(&team(preset), &mask).unwrap()
}

/// An angle's distance to another on the circle.
fn angle_gap(a: f64, b: f64) -> f64 {
    let d = (a - b).rem_euclid(std::f64::consts::TAU);
    d.min(std::f64::consts::TAU - d)
}

/// Brute force, independent of the solver: random gimbal angles for every agent and random
/// thrusts for all but four, then the four remaining thrusts from the four linear equations
/// `tau = 0`, `u_z = height` (thrust enters the wrench linearly). Kept when those thrusts are
/// admissible: each kept sample is an exactly attainable lateral force at `height`.
fn sampled_section(m: &AtlasModel, height: f64, samples: usize, seed: u64) -> Vec<(f64, f64)> {
    let b = m.agent_box;
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut out = Vec::new();
    for _ in 0..samples {
        let mut commands: Vec<GimbalCommand<f64>> = (0..m.len())
            .map(|_| GimbalCommand {
                thrust: rng.random_range(b.min_thrust..b.max_thrust),
                eta_x: rng.random_range(-b.sigma_x..=b.sigma_x),
                eta_y: rng.random_range(-b.sigma_y..=b.sigma_y),
            })
            .collect();
        // The rows tau_x, tau_y, tau_z, u_z of one agent at unit thrust.
        let unit = |i: usize, c: &[GimbalCommand<f64>]| {
            let mut one = vec![
                GimbalCommand {
                    thrust: 0.0,
                    ..c[0]
                };
                c.len()
            ];
            one[i] = GimbalCommand {
                thrust: 1.0,
                ..c[i]
            };
            let w = m.wrench(&one);
            Vector4::new(w[0], w[1], w[2], w[5])
        };
        let solved = [0, 1, 2, 3];
        let a = Matrix4::from_columns(&solved.map(|i| unit(i, &commands)));
        let mut rest = commands.clone();
        for i in solved {
            rest[i].thrust = 0.0;
        }
        let w = m.wrench(&rest);
        let rhs = Vector4::new(0.0, 0.0, 0.0, height) - Vector4::new(w[0], w[1], w[2], w[5]);
        let Some(t) = a.lu().solve(&rhs) else {
            continue;
        };
        if t.iter().all(|t| *t >= b.min_thrust && *t <= b.max_thrust) {
            for (k, i) in solved.iter().enumerate() {
                commands[*i].thrust = t[k];
            }
            let w = m.wrench(&commands);
            assert!(Vector4::new(w[0], w[1], w[2], w[5] - height).norm() < 1e-9);
            out.push((w[4].atan2(w[3]), w[3].hypot(w[4])));
        }
    }
    out
}

/// Every sampled attainable force lies inside the outer bound in its own direction, and the
/// inner bound reaches the farthest sample of each direction bin (to 0.1%).
fn check_against_sampling(preset: Preset, failed: &[usize], height_in_weights: f64) {
    let m = model(preset, failed);
    let height = height_in_weights * m.mass * 9.81;
    let samples = sampled_section(&m, height, 40_000, 11);
    assert!(
        samples.len() > 100,
        "{}: {} samples",
        preset.name(),
        samples.len()
    );
    let bins = 6;
    for bin in 0..bins {
        let centre = std::f64::consts::TAU * bin as f64 / bins as f64;
        let Some(&(angle, r)) = samples
            .iter()
            .filter(|(a, _)| angle_gap(*a, centre) < 0.2)
            .max_by(|x, y| x.1.total_cmp(&y.1))
        else {
            continue;
        };
        let bound = ray_radius(&m, height, &Vector3::zeros(), angle);
        let lower = bound.bracket.lower.unwrap();
        assert!(
            r <= bound.bracket.upper + 1e-9 * m.scale(),
            "{} bin {bin}: sample {r} beyond the outer bound {:?}",
            preset.name(),
            bound.bracket
        );
        assert!(
            lower >= r * (1.0 - 1e-3),
            "{} bin {bin}: inner {lower} short of the sample {r}",
            preset.name()
        );
        // The certificate: commands inside the boxes that make the wrench, checked with the
        // core's own gimbal map and effectiveness.
        let commands = bound.commands.unwrap();
        let t: TeamConfig<f64, 16> = team(preset);
        let mask = FailureMask::with_failed(failed).unwrap();
        let eff = t.effectiveness(&mask);
        let mut w = Vector6::zeros();
        for (slot, c) in m.agents.iter().zip(&commands) {
            assert!(m.agent_box.contains(c, 1e-12));
            w += eff.block(*slot).unwrap() * c.force();
        }
        let want = Vector6::new(
            0.0,
            0.0,
            0.0,
            lower * angle.cos(),
            lower * angle.sin(),
            height,
        );
        assert!((w - want).norm() < 1e-9 * m.scale(), "{w} vs {want}");
    }
}

#[test]
fn a4_inc_matches_sampling_at_hover_and_above() {
    check_against_sampling(Preset::A4Inc, &[], 1.0);
    check_against_sampling(Preset::A4Inc, &[], 1.5);
}

#[test]
fn a6_inc_and_a_degraded_a5_match_sampling() {
    check_against_sampling(Preset::A6Inc, &[], 1.0);
    check_against_sampling(Preset::A5Inc, &[2], 0.8);
}

/// Random attainable wrenches (any torque, any height) never exceed the outer bound of their own
/// cross-section: weak duality holds with the closed-form support functions.
#[test]
fn outer_bound_holds_for_random_wrenches_with_torque() {
    let m = model(Preset::A4DiamondInc, &[]);
    let b = m.agent_box;
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    for _ in 0..12 {
        let commands: Vec<GimbalCommand<f64>> = (0..m.len())
            .map(|_| GimbalCommand {
                // Thrusts near the top, where the boundary is.
                thrust: rng.random_range(0.6 * b.max_thrust..=b.max_thrust),
                eta_x: rng.random_range(-b.sigma_x..=b.sigma_x),
                eta_y: rng.random_range(-b.sigma_y..=b.sigma_y),
            })
            .collect();
        let w = m.wrench(&commands);
        let torque = Vector3::new(w[0], w[1], w[2]);
        let angle = w[4].atan2(w[3]);
        let bound = ray_radius(&m, w[5], &torque, angle);
        let r = w[3].hypot(w[4]);
        assert!(
            r <= bound.bracket.upper + 1e-9 * m.scale(),
            "{r} vs {:?}",
            bound.bracket
        );
        if let Some(lower) = bound.bracket.lower {
            assert!(lower <= bound.bracket.upper + 1e-9 * m.scale());
        }
    }
}

/// The first look at A4-Inc, `s = 1`: the cone's radius is 61-87% of the attainable one
/// at hover height, the worst at 45 degrees; at 1.5 `m_C g` it exceeds it along `x` and `y`.
#[test]
fn a4_inc_cone_against_the_attainable_set() {
    let m = model(Preset::A4Inc, &[]);
    let weight = m.mass * 9.81;
    let q = |height| SectionQuery {
        height,
        torque: Vector3::zeros(),
        directions: 8,
    };
    let hover = cross_section(&m, &q(weight));
    let cmp = compare(&m.afs, Relaxation::none(), &hover).unwrap();
    let range = cmp.ratio_range();
    assert!(range.lower > 0.6 && range.upper < 0.9, "{range:?}");
    let diagonal = &cmp.ratio[1];
    assert!(diagonal.upper < 0.65, "{diagonal:?}");
    // Conservative at hover: the cone is inside the attainable set.
    assert!(cmp.soundness.lower > 1.0 - 1e-9, "{:?}", cmp.soundness);
    assert!(cmp.conservatism.upper < 0.7, "{:?}", cmp.conservatism);
    let high = cross_section(&m, &q(1.5 * weight));
    let cmp = compare(&m.afs, Relaxation::none(), &high).unwrap();
    assert!(
        cmp.ratio[0].lower > 1.01 && cmp.ratio[2].lower > 1.01,
        "{:?}",
        cmp.ratio
    );
    assert!(cmp.soundness.upper < 1.0, "{:?}", cmp.soundness);
    // Brackets are tight enough to say so: closed along x and the diagonals; along y the
    // gimbal's curved eta_x faces leave an open bracket of under 5%.
    for (k, p) in high.points.iter().enumerate() {
        let width = p.radius.width() / p.radius.upper;
        let bound = if k % 4 == 2 { 0.05 } else { 1e-6 };
        assert!(width < bound, "direction {k}: {:?}", p.radius);
    }
}

/// `s*` on a sub-grid of the default one (heights 0.3 and 0.8 of the ceiling, four axis
/// directions) that holds the point where the full grid's value is decided (`docs/afs-atlas.json`:
/// 1.6 `m_C g`, 90 degrees): below it the cone is inside the attained points everywhere, above
/// the bracket's upper end it leaves the outer bound; and it is the core's table value
/// (`Preset::certified_relaxation`, generated by `scripts/afs-atlas.sh`), so a stale table fails.
#[test]
fn certified_relaxation_of_a4_inc() {
    let m = model(Preset::A4Inc, &[]);
    let range = HeightRange {
        from: 0.3,
        to: 0.8,
        heights: 2,
    };
    let cert = certified_relaxation(&m, &Vector3::zeros(), &range, 4).unwrap();
    assert!(cert.lower > 0.5 && cert.lower < 1.0, "{cert:?}");
    assert!(
        cert.upper >= cert.lower && cert.upper - cert.lower < 0.03,
        "{cert:?}"
    );
    let table = Preset::A4Inc
        .certified_relaxation::<f64>(None)
        .unwrap()
        .get();
    let want = (cert.lower * 1000.0).floor() / 1000.0;
    assert!(
        (table - want).abs() < 1e-9,
        "table {table}, atlas {}",
        cert.lower
    );
    let ceiling = cert.ceiling;
    let full = m.scale();
    assert!(
        (ceiling.lower.unwrap() - full).abs() < 1e-9 * full
            && ceiling.upper <= full * (1.0 + 1e-12)
    );
    let s = Relaxation::new(cert.lower).unwrap();
    for section in &cert.sections {
        for p in &section.points {
            let rc = cone_radius(&m.afs, s, section.query.height, p.angle);
            let tol = certify::CERTIFY_TOLERANCE * m.scale();
            assert!(rc <= p.radius.lower.unwrap() + tol * (1.0 + 1e-9));
        }
    }
    let above = Relaxation::new((cert.upper + 0.01).min(1.0)).unwrap();
    let leaves = cert.sections.iter().any(|section| {
        section
            .points
            .iter()
            .any(|p| cone_radius(&m.afs, above, section.query.height, p.angle) > p.radius.upper)
    });
    assert!(leaves || cert.upper >= 1.0);
    // Every catalogue team has a nominal value; rank-deficient degraded teams have none.
    for preset in Preset::ALL {
        assert!(
            preset.certified_relaxation::<f64>(None).is_some(),
            "{}",
            preset.name()
        );
    }
    assert!(Preset::A3Inc.certified_relaxation::<f64>(Some(0)).is_none());
}

/// The cone radius agrees with the core's membership test.
#[test]
fn cone_radius_is_the_cone_boundary() {
    let m = model(Preset::A6Inc, &[]);
    for s in [0.3, 0.5, 1.0] {
        let s = Relaxation::new(s).unwrap();
        for height in [5.0, 29.0, 50.0] {
            for k in 0..12 {
                let angle = k as f64 * 0.5;
                let r = cone_radius(&m.afs, s, height, angle);
                let at = |x: f64| Vector3::new(x * angle.cos(), x * angle.sin(), height);
                assert!(m.afs.contains(&at(r * (1.0 - 1e-9)), s));
                assert!(!m.afs.contains(&at(r * (1.0 + 1e-6) + 1e-9), s));
            }
        }
    }
}

/// The hover ceiling agrees with the core's hover certificate (`TeamConfig::hover_capability`),
/// an independent allocation: a team the core certifies has an attained ceiling above its
/// weight, and a team whose outer bound stays at its weight is not certified.
#[test]
fn hover_ceiling_agrees_with_the_core_hover_certificate() {
    for preset in [Preset::A4Inc, Preset::A5Inc, Preset::A6Inc, Preset::A8Con] {
        let t = team(preset);
        for lost in 0..t.len() {
            let m = model(preset, &[lost]);
            let weight = m.mass * 9.81;
            let ceiling = hover_ceiling(&m, &Vector3::zeros()).bracket;
            let mask = FailureMask::with_failed(&[lost]).unwrap();
            let core = t.hover_capability(&mask, 9.81).unwrap();
            let lower = ceiling.lower.unwrap();
            assert!(lower <= ceiling.upper + 1e-9 * m.scale());
            if core.capable {
                assert!(
                    lower > weight,
                    "{} minus {lost}: {ceiling:?}",
                    preset.name()
                );
            }
            if ceiling.upper <= weight * (1.0 + 1e-9) {
                assert!(!core.capable, "{} minus {lost}: {core:?}", preset.name());
            }
        }
    }
}

/// The request's arguments: a torque that is not three values, an unknown team or an
/// out-of-range setting is refused naming the argument.
#[test]
fn request_arguments_fail_by_name() {
    let mut two = AtlasRequest {
        team: "a4-inc".into(),
        failed: Vec::new(),
        each_failure: false,
        heights: vec![0.5, 1.0, 1.5],
        directions: 36,
        relaxation: 1.0,
        certify_heights: 9,
        torque: vec![0.0, 1.0],
        plots: None,
        json: None,
    };
    let e = run(&two).unwrap_err().to_string();
    assert!(e.contains("`torque`") && e.contains("three"), "{e}");
    two.torque = vec![0.0; 3];
    two.team = "a42".into();
    let e = run(&two).unwrap_err().to_string();
    assert!(
        e.contains("invalid argument `team`") && e.contains("a10-inc"),
        "{e}"
    );
    two.team = "a4-inc".into();
    two.directions = 2;
    let e = run(&two).unwrap_err().to_string();
    assert!(e.contains("invalid argument `directions`"), "{e}");
}
