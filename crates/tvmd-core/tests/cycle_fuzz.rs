//! Randomized control cycle (issue 13, "safe on any input"), in `f32` and in `f64`.
//!
//! Draws teams (the A4 presets and random teams of 3-16 agents, some invalid), controllers
//! (every allocator, random gains, gravity and rate limits, random failure masks), states and
//! references whose every field has a magnitude log-uniform up to the type's largest finite
//! value (plus 0, `MAX`, `MIN_POSITIVE`, subnormals, both signs, and now and then a NaN or a
//! non-rotation), and asserts per step:
//! - no panic; on `Ok` every output number is finite;
//! - every working agent's command is inside its `E_f` (`AdmissibleSet::contains` with
//!   `command_tolerance`), and the inversion clamped at most `command_tolerance`;
//! - `e_f` is what the forces produce: it equals `||u_fd - (M f)_f||` recomputed here from the
//!   allocation's forces (relative `64 eps`), and from the commands through the effectiveness
//!   (relative `1e4 eps` of the request plus what the agents can produce, the gimbal inverse's
//!   round-off);
//! - never `Ok` with every thrust zero while the force request `u_fr` is non-zero;
//! - errors are the documented variants, for the documented reasons, with the previous
//!   commands held; `Overflow` (the safety net) never trips;
//! - invalid teams and failure masks are refused with a `ConfigError`, never a panic.
//!
//! Steps per type: `TVMD_FUZZ_STEPS` (default 5,000, for a debug `cargo test`);
//! `scripts/test.sh` runs 1,000,000 per type in release. The seed is `TVMD_FUZZ_SEED`
//! (default fixed, so a failure reproduces). The counts are printed (`--nocapture`).

use std::collections::BTreeMap;

use nalgebra::{Matrix3, UnitQuaternion, Vector3, Vector6};
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use tvmd_core::allocation::AllocatorOptions;
use tvmd_core::command::command_tolerance;
use tvmd_core::team::presets;
use tvmd_core::{
    AgentLimits, AgentSpec, AnyAllocator, ControlOutput, Controller, ControllerSettings,
    FailureMask, Gains, InputError, Navigator, RateLimits, Real, Reference, RigidState, TeamConfig,
};

const N: usize = 16;

type Ctl<T> = Controller<T, N, AnyAllocator<T, N>>;

fn env_u64(name: &str, default: u64) -> u64 {
    std::env::var(name)
        .ok()
        .and_then(|s| s.replace('_', "").parse().ok())
        .unwrap_or(default)
}

fn to_f64<T: Real>(x: T) -> f64 {
    x.to_subset().unwrap_or(f64::NAN)
}

/// The largest finite value of `T`, as `f64`.
fn max_of<T: Real>() -> f64 {
    T::max_value().map(to_f64).unwrap_or(f64::MAX)
}

/// `x` in `T`, clamped to `T`'s finite range so a draw never rounds to infinity.
fn conv<T: Real>(x: f64) -> T {
    let m = max_of::<T>();
    nalgebra::convert(if x.is_finite() { x.clamp(-m, m) } else { x })
}

/// The smallest positive subnormal of `T`, as `f64`.
fn tiny_of<T: Real>() -> f64 {
    if max_of::<T>() > 1e300 {
        f64::from_bits(1)
    } else {
        f64::from(f32::from_bits(1))
    }
}

/// A signed magnitude: special values, or log-uniform from the smallest subnormal to `max`
/// (`T::MAX`, or a few times the controller's input bound to probe just below and above it).
fn magnitude<T: Real>(rng: &mut StdRng, max: f64) -> f64 {
    let tiny = tiny_of::<T>();
    let min_positive = if max > 1e300 {
        f64::MIN_POSITIVE
    } else {
        f64::from(f32::MIN_POSITIVE)
    };
    let x = match rng.random_range(0..20) {
        0 => 0.0,
        1 => max,
        2 => max_of::<T>(),
        3 if rng.random_bool(0.5) => min_positive,
        3 => tiny * f64::from(rng.random_range(1..1000)),
        4 => 1.0,
        _ => {
            let (lo, hi) = (tiny.log10(), max.log10());
            10f64.powf(rng.random_range(lo..hi)).min(max)
        }
    };
    if rng.random_bool(0.5) {
        -x
    } else {
        x
    }
}

/// A vector input: zero, of flight-like size, or with one or every component extreme (up to
/// `max`). `calm` makes the flight-like size likely (so that most steps run the whole cycle).
fn vector<T: Real>(rng: &mut StdRng, typical: f64, max: f64, calm: bool) -> Vector3<T> {
    let pick = if calm && rng.random_bool(0.85) {
        rng.random_range(0..2)
    } else {
        rng.random_range(0..4)
    };
    match pick {
        0 => Vector3::zeros(),
        1 => Vector3::from_fn(|_, _| conv(rng.random_range(-typical..typical))),
        2 => {
            // One component extreme.
            let mut v = Vector3::from_fn(|_, _| conv(rng.random_range(-typical..typical)));
            v[rng.random_range(0..3)] = conv(magnitude::<T>(rng, max));
            v
        }
        _ => Vector3::from_fn(|_, _| conv(magnitude::<T>(rng, max))),
    }
}

/// A rotation, now and then a near-rotation (accepted), a non-rotation or NaN (refused).
fn attitude<T: Real>(rng: &mut StdRng, bad: &mut bool) -> Matrix3<T> {
    let q = UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(
        rng.random_range(-1.0..1.0),
        rng.random_range(-1.0..1.0),
        rng.random_range(-1.0..1.0),
        rng.random_range(-1.0..1.0f64),
    ));
    let r = if rng.random_bool(0.5) {
        Matrix3::identity()
    } else {
        *q.to_rotation_matrix().matrix()
    };
    let r = match rng.random_range(0..200) {
        0 => {
            *bad = true;
            r * 2.0
        }
        1 => {
            *bad = true;
            Matrix3::zeros()
        }
        2 => {
            *bad = true;
            let mut r = r;
            r[(1, 2)] = f64::NAN;
            r
        }
        _ => r,
    };
    r.map(conv)
}

/// A random scalar in `[lo, hi)`, log-uniform.
fn log_uniform(rng: &mut StdRng, lo: f64, hi: f64) -> f64 {
    10f64.powf(rng.random_range(lo.log10()..hi.log10()))
}

/// A team: a preset, a random valid-looking one, or a deliberately broken one.
fn team<T: Real>(rng: &mut StdRng) -> Result<TeamConfig<T, N>, tvmd_core::ConfigError> {
    match rng.random_range(0..6) {
        0 => return presets::a4_inc(),
        1 => return presets::a4_con(),
        _ => {}
    }
    let n = rng.random_range(3..=N);
    let arm = log_uniform(rng, 0.05, 5.0);
    let broken = rng.random_range(0..8) == 0;
    let mut agents: Vec<AgentSpec<T>> = (0..n)
        .map(|_| {
            AgentSpec::new(
                Vector3::new(
                    rng.random_range(-arm..arm),
                    rng.random_range(-arm..arm),
                    rng.random_range(-0.1 * arm..0.1 * arm),
                )
                .map(conv),
                rng.random_range(-4..4),
                conv(log_uniform(rng, 0.05, 10.0)),
            )
        })
        .collect();
    let mut sigma = [
        rng.random_range(0.05..std::f64::consts::FRAC_PI_2),
        rng.random_range(0.05..std::f64::consts::FRAC_PI_2),
    ];
    if rng.random_range(0..8) == 0 {
        sigma[rng.random_range(0..2)] = std::f64::consts::FRAC_PI_2;
    }
    let mut max_thrust = log_uniform(rng, 1.0, 200.0);
    if broken {
        let i = rng.random_range(0..n);
        match rng.random_range(0..7) {
            0 => agents[i].mass = conv(-1.0),
            1 => agents[i].mass = conv(f64::NAN),
            2 => agents[i].mass = conv(f64::MAX),
            3 => agents[i].position.x = conv(f64::INFINITY),
            4 => sigma[0] = 2.0,
            5 => max_thrust = -1.0,
            _ => {
                agents[i].inertia =
                    Matrix3::new(1.0, 2.0, 0.0, 0.0, -1.0, 0.0, 0.0, 0.0, 1.0).map(conv)
            }
        }
    }
    let mut limits = AgentLimits::new(conv(sigma[0]), conv(sigma[1]), conv(max_thrust))?;
    if rng.random_range(0..6) == 0 {
        limits = limits.with_min_thrust(conv(max_thrust * rng.random_range(0.0..0.2)))?;
    }
    TeamConfig::new(&agents, limits, Navigator::default())
}

fn allocator<T: Real>(rng: &mut StdRng, clarabel: bool) -> AnyAllocator<T, N> {
    let mut options = AllocatorOptions::<T, N>::default();
    let name = if clarabel {
        if rng.random_bool(0.5) {
            "clarabel"
        } else {
            "clarabel-sequential"
        }
    } else {
        match rng.random_range(0..4) {
            0 => "pseudo-inverse",
            3 => "exact-boundary-redistribution",
            1 => {
                options.agent_weights =
                    Some(std::array::from_fn(|_| conv(log_uniform(rng, 0.1, 10.0))));
                "weighted-pseudo-inverse"
            }
            _ => "redistributed-pseudo-inverse",
        }
    };
    AnyAllocator::from_name(name, &options).expect("the names and options are valid")
}

/// Random settings; gains the validation refuses (e.g. a product that overflows the type)
/// come back as the `ConfigError`.
fn settings<T: Real>(rng: &mut StdRng) -> Result<ControllerSettings<T>, tvmd_core::ConfigError> {
    let mut s = ControllerSettings::paper();
    if rng.random_bool(0.5) {
        let mut d = || conv(log_uniform(rng, 1e-2, 1e2));
        s.gains = Gains::diagonal(
            [d(), d(), d()],
            [d(), d(), d()],
            [d(), d(), d(), d(), d(), d()],
        )?;
    }
    if rng.random_bool(0.3) {
        s.gravity = conv(rng.random_range(1.0..30.0));
    }
    if rng.random_bool(0.3) {
        s.rate_limits = Some(RateLimits::new(conv(5.0), conv(5.0))?);
    }
    Ok(s)
}

/// Counts of one run.
#[derive(Default)]
struct Counts {
    steps: u64,
    ok: u64,
    errors: BTreeMap<&'static str, u64>,
    teams_rejected: u64,
    masks_rejected: u64,
    controllers: u64,
    clarabel_steps: u64,
    unusable: u64,
    settings_rejected: u64,
}

/// `||v||` scaled (the test's own, independent of the crate's).
fn norm<T: Real>(v: &[T]) -> f64 {
    let m = v.iter().fold(0.0f64, |m, x| m.max(to_f64(*x).abs()));
    if m == 0.0 {
        return 0.0;
    }
    v.iter()
        .map(|x| (to_f64(*x) / m).powi(2))
        .sum::<f64>()
        .sqrt()
        * m
}

fn all_finite<T: Real, const K: usize>(out: &ControlOutput<T, K>) -> bool {
    let f = |s: &[T]| s.iter().all(|x| x.is_finite());
    out.commands
        .iter()
        .all(|c| f(&[c.eta_x, c.eta_y, c.thrust, c.omega]))
        && out.allocation.forces.iter().all(|v| f(v.as_slice()))
        && f(out.allocation.wrench.as_slice())
        && f(&[
            out.allocation.e_f,
            out.allocation.wrench_error,
            out.command_clamp,
            out.planner.theta,
            out.projection.t_tf,
            out.projection.t_eta,
            out.law.v_r,
            out.law.v_x,
        ])
        && f(out.planner.r_d.as_slice())
        && f(out.projection.force.as_slice())
        && f(out.f_r.as_slice())
        && f(out.law.u_r.as_slice())
        && f(out.law.u_d.as_slice())
        && f(out.law.e_xi.as_slice())
        && f(out.law.e_r.as_slice())
        && f(out.law.e_x.as_slice())
}

/// The per-step assertions on a successful cycle.
fn check_ok<T: Real>(
    c: &Ctl<T>,
    sets: &[tvmd_core::AdmissibleSet<T>; N],
    out: &ControlOutput<T, N>,
    context: &dyn Fn() -> String,
) {
    assert!(all_finite(out), "non-finite output: {}", context());
    // Allocators return admissible forces: the inversion clamps round-off only.
    assert!(
        out.command_clamp <= command_tolerance::<T>(),
        "clamp {:?}: {}",
        out.command_clamp,
        context()
    );
    let e = c.effectiveness();
    let tol = command_tolerance::<T>();
    let mut from_commands = [Vector3::zeros(); N];
    for (i, (cmd, set)) in out.commands.iter().zip(sets).enumerate() {
        if e.block(i).is_some() {
            assert!(
                set.contains(&cmd.gimbal(), tol),
                "agent {i} command {cmd:?} outside E_f {set:?}: {}",
                context()
            );
            from_commands[i] = cmd.force();
        } else {
            assert_eq!(cmd.thrust, T::zero(), "failed agent {i} has thrust");
        }
    }
    let eps = to_f64(T::default_epsilon());
    let u_fd = out.law.u_d.fixed_rows::<3>(3).into_owned();
    let reach: f64 = e
        .blocks()
        .iter()
        .zip(sets)
        .filter_map(|(b, s)| {
            b.as_ref()
                .map(|b| to_f64(s.thrust().hi) * 3.0 * to_f64(b.amax()))
        })
        .sum();
    let residual = |forces: &[Vector3<T>; N]| {
        let w: Vector6<f64> = e
            .blocks()
            .iter()
            .zip(forces)
            .filter_map(|(b, f)| b.as_ref().map(|b| (b * f).map(to_f64)))
            .fold(Vector6::zeros(), |a, u| a + u);
        let d = [
            to_f64(u_fd.x) - w[3],
            to_f64(u_fd.y) - w[4],
            to_f64(u_fd.z) - w[5],
        ];
        norm::<f64>(&d)
    };
    let e_f = to_f64(out.allocation.e_f);
    let scale = norm(u_fd.as_slice()) + reach;
    let direct = residual(&out.allocation.forces);
    assert!(
        (e_f - direct).abs() <= 64.0 * eps * scale,
        "e_f {e_f} but the allocation's forces leave {direct}: {}",
        context()
    );
    let through_commands = residual(&from_commands);
    assert!(
        (e_f - through_commands).abs() <= 1e4 * eps * scale,
        "e_f {e_f} but the commands leave {through_commands}: {}",
        context()
    );
    let u_fr = out.law.u_r.fixed_rows::<3>(3).into_owned();
    if u_fr != Vector3::zeros() {
        assert!(
            out.commands.iter().any(|c| c.thrust > T::zero()),
            "Ok with every thrust zero for u_fr = {u_fr:?}: {}",
            context()
        );
    }
}

fn fuzz<T: Real>(label: &str, steps: u64, seed: u64, clarabel: bool) -> Counts {
    let mut rng = StdRng::seed_from_u64(seed);
    let mut counts = Counts::default();
    while counts.steps < steps {
        let team = match team::<T>(&mut rng) {
            Ok(t) => t,
            Err(_) => {
                // A typed ConfigError, no panic: that is the assertion.
                counts.teams_rejected += 1;
                continue;
            }
        };
        let use_clarabel = clarabel && rng.random_range(0..10) == 0;
        let settings = match settings(&mut rng) {
            Ok(s) => s,
            Err(_) => {
                counts.settings_rejected += 1;
                continue;
            }
        };
        let mut c = match Controller::new(team, settings, allocator(&mut rng, use_clarabel)) {
            Ok(c) => c,
            Err(_) => {
                counts.teams_rejected += 1;
                continue;
            }
        };
        counts.controllers += 1;
        if rng.random_bool(0.3) {
            let mut mask = FailureMask::<N>::none();
            for _ in 0..rng.random_range(1..=2) {
                let _ = mask.set(rng.random_range(0..team.len() + 1), true);
            }
            if c.set_failures(mask).is_err() {
                counts.masks_rejected += 1;
            }
        }
        let limit = to_f64(c.input_limit());
        assert!(limit.is_finite() && limit >= 0.0, "input limit {limit}");
        if limit == 0.0 {
            // A team whose totals overflow (e.g. an agent of mass MAX) is refused by the team
            // and plant validation, so a usable controller always has a positive bound.
            counts.unusable += 1;
            continue;
        }
        let run = if use_clarabel { 10 } else { 40 };
        for _ in 0..run {
            let mut bad_attitude = false;
            let mut non_finite = false;
            // Half the steps draw extremes up to MAX, half up to 4x the input bound.
            let max = if rng.random_bool(0.5) {
                max_of::<T>()
            } else {
                (limit * 4.0).min(max_of::<T>())
            };
            let calm = rng.random_bool(0.6);
            let mut v = |typical| vector::<T>(&mut rng, typical, max, calm);
            let (position, angular_velocity, velocity) = (v(10.0), v(5.0), v(5.0));
            let (r_position, r_velocity, r_acceleration) = (v(10.0), v(5.0), v(5.0));
            let (r_angular_velocity, r_angular_acceleration) = (v(5.0), v(5.0));
            let mut state = RigidState {
                position,
                attitude: attitude(&mut rng, &mut bad_attitude),
                angular_velocity,
                velocity,
            };
            let mut reference = Reference {
                position: r_position,
                velocity: r_velocity,
                acceleration: r_acceleration,
                attitude: attitude(&mut rng, &mut bad_attitude),
                angular_velocity: r_angular_velocity,
                angular_acceleration: r_angular_acceleration,
            };
            if rng.random_range(0..200) == 0 {
                non_finite = true;
                let v = if rng.random_bool(0.5) {
                    f64::NAN
                } else {
                    f64::INFINITY
                };
                match rng.random_range(0..3) {
                    0 => state.velocity.y = conv(v),
                    1 => reference.acceleration.z = conv(v),
                    _ => state.position.x = conv(v),
                }
            }
            if rng.random_range(0..4) == 0 {
                // Track the reference (the flight case), keeping the extremes elsewhere.
                reference.position = state.position;
            }
            let inputs = [
                state.position,
                state.velocity,
                state.angular_velocity,
                reference.position,
                reference.velocity,
                reference.acceleration,
                reference.angular_velocity,
                reference.angular_acceleration,
            ];
            let beyond = inputs
                .iter()
                .flat_map(|v| v.iter())
                .any(|x| to_f64(*x).abs() > limit);
            let sets = c.admissible_sets();
            let previous = *c.previous_commands();
            counts.steps += 1;
            if use_clarabel {
                counts.clarabel_steps += 1;
            }
            let allocator_name = c.allocator().name();
            let context = || {
                format!(
                    "{label}, allocator {allocator_name}, state {state:?}, reference {reference:?}"
                )
            };
            match c.step(&state, &reference) {
                Ok(out) => {
                    counts.ok += 1;
                    assert!(
                        !bad_attitude && !non_finite && !beyond,
                        "Ok on a bad input: {}",
                        context()
                    );
                    check_ok(&c, &sets, &out, &context);
                }
                Err(e) => {
                    assert_eq!(
                        e.commands, previous,
                        "the held commands are the previous ones"
                    );
                    let name = match e.error {
                        InputError::NonFinite { .. } => {
                            assert!(non_finite || bad_attitude, "{}: {}", e, context());
                            "NonFinite"
                        }
                        InputError::NotRotation { .. } => {
                            assert!(bad_attitude, "{}: {}", e, context());
                            "NotRotation"
                        }
                        InputError::OutOfRange { limit: l, .. } => {
                            assert!(beyond && l == limit, "{}: {}", e, context());
                            "OutOfRange"
                        }
                        InputError::Unattainable { .. } => "Unattainable",
                        InputError::Overflow { .. } => {
                            panic!("the safety net tripped: {}: {}", e, context())
                        }
                    };
                    *counts.errors.entry(name).or_default() += 1;
                }
            }
            if counts.steps >= steps {
                break;
            }
        }
    }
    println!(
        "cycle_fuzz {label}: {} steps ({} with clarabel), {} Ok, errors {:?}; {} controllers, {} teams, {} settings and {} failure masks rejected with a ConfigError, {} teams with overflowing totals skipped",
        counts.steps,
        counts.clarabel_steps,
        counts.ok,
        counts.errors,
        counts.controllers,
        counts.teams_rejected,
        counts.settings_rejected,
        counts.masks_rejected,
        counts.unusable
    );
    counts
}

fn run<T: Real>(label: &str, seed_offset: u64) {
    let steps = env_u64("TVMD_FUZZ_STEPS", 5_000);
    let seed = env_u64("TVMD_FUZZ_SEED", 13) + seed_offset;
    let counts = fuzz::<T>(label, steps, seed, cfg!(feature = "clarabel"));
    assert_eq!(counts.steps, steps);
    // The draws exercise both outcomes.
    assert!(counts.ok > 0 && counts.steps > counts.ok);
}

#[test]
fn random_cycles_f32() {
    run::<f32>("f32", 0);
}

#[test]
fn random_cycles_f64() {
    run::<f64>("f64", 1);
}
