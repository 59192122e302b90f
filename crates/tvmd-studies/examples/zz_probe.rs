use tvmd_scenario::*;
use tvmd_studies::montecarlo::{Conditions, Distributions, Draw};
fn main() {
    for k in (0..1000u64).filter(|k| k % 3 == 0 && (k / 3) % 3 == 2) {
        let mut s = Scenario::default();
        s.team.preset = Some("a4-inc".into());
        s.fault_detection = Some(FaultDetectionConfig::with_response(
            FaultResponseConfig::Mask,
        ));
        let mut s = Draw::new(&Distributions::default(), 47, k, 4)
            .apply(&s)
            .unwrap();
        Conditions::default().apply(&mut s, 47, k);
        let r = tvmd_sim::run_scenario(&s, None, None).unwrap();
        let f = r.summary.fault.unwrap();
        if f.first_suspected.is_none() {
            continue;
        }
        println!("k {k}: {:?}", f.first_confirmed);
        let t0 = f.first_suspected.unwrap().time;
        for x in r
            .samples
            .iter()
            .filter(|x| x.t >= t0 - 0.1 && x.t <= t0 + 0.1)
        {
            let g = x
                .commands
                .iter()
                .map(|c| format!("({:+.2},{:+.2},{:.1})", c.eta_x, c.eta_y, c.thrust))
                .collect::<Vec<_>>()
                .join(" ");
            let a = x
                .actual
                .iter()
                .map(|c| format!("({:+.2},{:+.2},{:.1})", c.eta_x, c.eta_y, c.thrust))
                .collect::<Vec<_>>()
                .join(" ");
            let fd = x.fault.unwrap();
            println!("  {:.2} {:.1} {:?} {:?} {:?} eff {:?} sat {:?} z {:.2}\n     cmd {g}\n     act {a}", x.t, fd.statistic, fd.verdict, fd.agent, fd.kind, fd.efficiency, x.saturated_agents, x.position[2]);
        }
    }
}
