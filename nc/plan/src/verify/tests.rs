//! The resumed check ([`check_from`]) against the full one ([`check`]).

use super::*;
use crate::plan::plan;
use nc_geom::kinematics::MachineKinematics;
use nc_geom::segment::build;

/// A program of several G01 and G06.5 blocks, about 16 s at the paper machine's limits.
const PROGRAM: &str = "\
N10 G01 X0 Y0 Z0 I0 J0 K1 F600
N20 G01 X40 Y10 Z0 I0.1 J0 K1
N30 G06.5 P3 X40 Y10 Z0 U40.1 V10 W1 R1 K0 F900
X60 Y30 Z5 U60.2 V30.1 W6 R1 K0
X80 Y0 Z5 U80 V0.2 W6 R2 K0
X100 Y20 Z0 U100 V20 W1 R1 K0
K1 K1 K1 K1
N40 G01 X20 Y40 Z10 I0 J0 K1 F600
N50 G01 X0 Y0 Z0
";

fn setup(velocity_x: f64) -> (Path, FeedProfile, MachineKinematics, PlanConfig, Vec<bool>) {
    let (mut cfg, bl) = crate::fixtures::small_mill(0.002);
    let kin = MachineKinematics::Paper;
    let program = nc_lang::parse(PROGRAM).expect("the test program parses");
    let path = build(&program, &kin, &bl).expect("the test program builds");
    let profile = plan(&path, &kin, &cfg).expect("the test program plans");
    // Checked against a lower X limit, the same profile breaks it in many places.
    cfg.axes[0].velocity = velocity_x;
    let smooth = smooth_junctions(&path, &kin, &cfg);
    (path, profile, kin, cfg, smooth)
}

/// The same profile with every phase from `from` on made faster: a replanned round that
/// changed the plan from there.
fn changed(profile: &FeedProfile, from: usize) -> FeedProfile {
    let mut p = profile.clone();
    for ph in &mut p.phases[from..] {
        ph.v0 *= 1.25;
        ph.j *= 1.5;
    }
    p
}

#[test]
fn a_resumed_check_measures_what_the_full_check_measures() {
    for velocity_x in [250.0, 8.0] {
        let (path, profile, kin, cfg, smooth) = setup(velocity_x);
        assert!(profile.duration > 4.0 * MARK_EVERY as f64 * cfg.period);
        // A mark every period: a resume one period too late changes what is measured.
        let check_every =
            |p: &FeedProfile, e: Option<Earlier>| check_marked(&path, p, &kin, &cfg, &smooth, e, 1);
        let (first, trace) = check_every(&profile, None);
        assert_eq!(first, check(&path, &profile, &kin, &cfg, &smooth));
        assert_eq!(
            check_from(&path, &profile, &kin, &cfg, &smooth, None)
                .1
                .marks
                .len(),
            (first.margins.cycles / MARK_EVERY) as usize
        );
        if velocity_x < 250.0 {
            assert!(first.violations.len() > 10, "the lower limit is broken");
        }
        // A change at every phase.
        for from in 0..profile.phases.len() {
            let next = changed(&profile, from);
            let earlier = Earlier {
                offset: 0,
                phases: &profile.phases,
                checked: &first,
                trace: &trace,
            };
            let (resumed, next_trace) = check_every(&next, Some(earlier));
            let full = check_every(&next, None);
            assert_eq!(resumed, full.0, "changed from phase {from}");
            assert_eq!(next_trace.marks.len(), full.1.marks.len());
            for (a, b) in next_trace.marks.iter().zip(&full.1.marks) {
                assert_eq!(a.ip, b.ip, "changed from phase {from}");
                assert_eq!(a.violations, b.violations);
            }
            // What was taken over lies before the change.
            let kept = next_trace
                .marks
                .iter()
                .zip(&trace.marks)
                .take_while(|(a, b)| a.ip == b.ip)
                .count();
            let at = next.phases[from].t0;
            assert!(kept == 0 || trace.marks[kept - 1].win[3].t < at);
        }
    }
}
