//! `tvmd-sim px4`: PX4 SITL flies a scenario on tvmd's plant (crate tvmd-px4).

use std::time::Duration;

use tvmd_log::paths::check_outputs;
use tvmd_px4::bridge::Pacing;
use tvmd_px4::launch::{Px4Launch, Simulator};
use tvmd_px4::{fly_px4, write_report, FlightPlan, Px4Flight};
use tvmd_scenario::Scenario;

use crate::args::Px4Args;
use crate::error::CliError;

pub fn cmd_px4(a: Px4Args) -> Result<(), CliError> {
    let px4 = |e: tvmd_px4::Px4Error| CliError::Other(e.to_string());
    let scenario = Scenario::load(&a.scenario)?;
    let plan = FlightPlan::from_file(&a.flight).map_err(px4)?;
    let report_path = a.out.with_extension("px4.json");
    check_outputs(
        &[
            ("the log (--out)".into(), a.out.as_path()),
            ("the report".into(), report_path.as_path()),
        ],
        &[("flight file".into(), a.flight.as_path())],
    )?;
    let launch = a.px4_dir.map(|tree| Px4Launch {
        tree,
        build: a.px4_build.clone(),
        autostart: if a.sih { 10040 } else { a.autostart },
        params: a.params,
        work_dir: a.out.with_extension("px4"),
        instance: a.instance,
        simulator: if a.sih {
            Simulator::Sih
        } else {
            Simulator::Tvmd
        },
    });
    if let Some(l) = &launch {
        tvmd_px4::launch::px4_binary(&l.tree, &l.build).map_err(px4)?;
        if a.sih {
            let report =
                tvmd_px4::run::fly_sih(&plan, l, scenario.duration, &a.out.with_extension("ulg"))
                    .map_err(px4)?;
            write_report(&report_path, &report).map_err(px4)?;
            println!(
                "flown:    {:.1} s on SIH in {:.1} s wall",
                report.sim_time, report.wall_time
            );
            println!("report:   {}", report_path.display());
            if let Some(u) = &report.ulog {
                println!("ulog:     {u}");
            }
            return Ok(());
        }
    }
    let flight = Px4Flight {
        scenario,
        plan,
        instance: a.instance,
        log: Some(a.out.clone()),
        launch,
        pacing: if a.real_time {
            Pacing::RealTime
        } else {
            Pacing::Lockstep
        },
        connect_timeout: Duration::from_secs_f64(a.connect_timeout),
        stall_timeout: Duration::from_secs_f64(a.stall_timeout),
        boot_timeout: Duration::from_secs_f64(a.connect_timeout),
    };
    let (report, error) = fly_px4(&flight, &mut |port| {
        println!("px4:      waiting for PX4 on TCP 127.0.0.1:{port}");
    })
    .map_err(px4)?;
    write_report(&report_path, &report).map_err(px4)?;
    match report.pacing {
        Pacing::Lockstep => println!(
            "flown:    {:.1} s simulated in {:.1} s wall ({} lockstep)",
            report.sim_time,
            report.wall_time,
            report
                .realtime_factor
                .map_or("no".into(), |f| format!("{f:.2}x real time in")),
        ),
        Pacing::RealTime => println!(
            "flown:    {:.1} s simulated in {:.1} s wall (real time; {} ticks late)",
            report.sim_time, report.wall_time, report.lockstep.late_ticks,
        ),
    }
    for w in &report.windows {
        println!("{}", serde_json::to_string(w)?);
    }
    println!("report:   {}", report_path.display());
    println!("log:      {}", a.out.display());
    if let Some(u) = &report.ulog {
        println!("ulog:     {u}");
    }
    match error {
        Some(e) => Err(CliError::Other(e.to_string())),
        None => Ok(()),
    }
}
