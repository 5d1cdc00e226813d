//! Segments built from parsed programs carry what the program commands beside the motion.

use nc_geom::kinematics::MachineKinematics;
use nc_lang::{parse_with, Setup};

/// Spindle and coolant along the segments: the words before each block apply along it; the
/// first feed move after a start, a reversal or a new speed waits for the spindle (rapids
/// before it do not), and a stop clears the wait.
#[test]
fn segments_carry_spindle_and_coolant_and_the_first_feed_move_waits() {
    let (_, limits) = nc_plan::fixtures::small_mill(0.002);
    let src = "G00 X0 Y0 Z50\nS8000 M03 M08\nG00 X10\nG01 X20 F600\nG01 X30\n\
               S9000\nG01 X40\nM05 M09\nS100 M03\nM05\nG01 X50\nM04\nG00 X60\nG01 X70\n";
    let p = parse_with(src, &Setup::default()).unwrap();
    let path = nc_geom::segment::build(&p, &MachineKinematics::Paper, &limits).unwrap();
    let seen: Vec<(u32, f64, bool, bool)> = path
        .segments
        .iter()
        .map(|s| (s.src.line, s.aux.spindle_rpm, s.aux.flood, s.wait.spindle))
        .collect();
    assert_eq!(
        seen,
        [
            (3, 8000.0, true, false),
            (4, 8000.0, true, true),
            (5, 8000.0, true, false),
            (7, 9000.0, true, true),
            (11, 0.0, false, false),
            (13, -100.0, false, false),
            (14, -100.0, false, true),
        ]
    );
    assert!(path.segments.iter().all(|s| s.stop || !s.wait.spindle));
}
