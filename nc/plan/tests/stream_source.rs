//! A program streamed (`nc_plan::stream::Source`: parser entries, builder, planner and cutter a
//! line at a time) gives the chunks that cutting the whole program's plan gives, but for
//! what only the whole plan knows (each chunk's `vmax_ahead`, bounded by the machine's
//! speed cap instead), and refuses what the whole pipeline refuses, at the same place.
#![allow(clippy::vec_box)] // chunks travel boxed

use nc_follow::{stop_length, Chunk};
use nc_geom::kinematics::MachineKinematics;
use nc_geom::segment::{build, BuildLimits};
use nc_lang::{Entries, Setup, StrLines};
use nc_plan::config::PlanConfig;
use nc_plan::plan::plan;
use nc_plan::stream::{cut, Machine, Source, StreamError};

const PERIOD: f64 = 0.002;
const DEPTH: usize = 64;

fn streamed(
    text: &str,
    kin: &MachineKinematics,
    cfg: &PlanConfig,
    bl: &BuildLimits,
) -> Result<Vec<Box<Chunk>>, StreamError> {
    let setup = Setup::default();
    let entries = Entries::new(StrLines::new(text), &setup);
    let machine = Machine {
        kin,
        build: bl,
        plan: cfg,
    };
    let mut source = Source::new(entries, machine, DEPTH);
    let mut out = Vec::new();
    while let Some(c) = source.next_chunk()? {
        out.push(c);
    }
    assert!(source.start().is_some() && source.end_joints().is_some());
    Ok(out)
}

/// The whole pipeline: parse, build, plan, cut with the stream's chunk length.
fn whole(
    text: &str,
    kin: &MachineKinematics,
    cfg: &PlanConfig,
    bl: &BuildLimits,
) -> Result<Vec<Box<Chunk>>, String> {
    let program = nc_lang::parse(text).map_err(|e| e.to_string())?;
    let path = build(&program, kin, bl).map_err(|e| e.to_string())?;
    let profile = plan(&path, kin, cfg).map_err(|e| e.to_string())?;
    let vmax = bl.speed_cap() * (1.0 + 1e-6);
    let len = stop_length(vmax, &nc_plan::verify::ceiling(cfg), &cfg.hold(), DEPTH);
    Ok(cut(path, &profile, len).1)
}

fn same_chunks(
    name: &str,
    text: &str,
    kin: &MachineKinematics,
    cfg: &PlanConfig,
    bl: &BuildLimits,
) -> usize {
    let s = streamed(text, kin, cfg, bl).map_err(|e| e.to_string());
    let w = whole(text, kin, cfg, bl);
    let (s, w) = match (s, w) {
        (Ok(s), Ok(w)) => (s, w),
        (Err(a), Err(b)) => {
            assert_eq!(a, b, "{name}: refused otherwise");
            return 0;
        }
        (s, w) => panic!(
            "{name}: streamed {:?}, whole {:?}",
            s.map(|c| c.len()),
            w.map(|c| c.len())
        ),
    };
    assert_eq!(s.len(), w.len(), "{name}: chunk count");
    let cap = bl.speed_cap() * (1.0 + 1e-6);
    for (a, b) in s.iter().zip(&w) {
        let at = format!("{name}, chunk {}", a.index);
        assert_eq!(a.index, b.index, "{at}");
        assert_eq!(a.segments, b.segments, "{at}");
        assert_eq!(a.starts, b.starts, "{at}");
        assert_eq!((a.s0, a.s1), (b.s0, b.s1), "{at}");
        assert_eq!(a.phases, b.phases, "{at}");
        assert_eq!(
            (a.t_start, a.t_end, a.t_arrive),
            (b.t_start, b.t_end, b.t_arrive),
            "{at}"
        );
        assert_eq!(
            (a.vmax, a.rests_at_end, a.last),
            (b.vmax, b.rests_at_end, b.last),
            "{at}"
        );
        assert!(a.vmax <= cap, "{at}: {} over the cap {cap}", a.vmax);
        assert!(a.vmax_ahead >= b.vmax_ahead && a.vmax_ahead == cap, "{at}");
    }
    s.len()
}

#[test]
fn a_streamed_program_gives_the_chunks_of_its_whole_plan() {
    let kin = MachineKinematics::Paper;
    let (cfg, bl) = nc_plan::fixtures::small_mill(PERIOD);
    let mut chunks = 0;
    for rel in nc_plan::fixtures::TEST_PROGRAMS {
        chunks += same_chunks(rel, &nc_plan::fixtures::test_program(rel), &kin, &cfg, &bl);
    }
    assert!(chunks > 20, "{chunks} chunks");
}

#[test]
fn a_streamed_program_is_refused_where_the_whole_one_is() {
    let kin = MachineKinematics::Paper;
    let (cfg, bl) = nc_plan::fixtures::adversarial_mill(PERIOD);
    let text = nc_plan::fixtures::test_program("paper-example.nc");
    let end = text
        .lines()
        .position(|l| l.starts_with("M30") || l.starts_with("M02"))
        .expect("ends");
    let mut lines: Vec<&str> = text.lines().collect();
    // Past the travel (planner), a syntax error, a move the machine cannot make (builder).
    for bad in ["G01 X400", "G01 X1 Y$", "G01 A10"] {
        let mut l = lines.clone();
        l.insert(end, bad);
        let t = l.join("\n");
        let s = streamed(&t, &kin, &cfg, &bl).expect_err(bad);
        assert_eq!(s.pos().line as usize, end + 1, "{bad}: {s}");
        assert_eq!(same_chunks(bad, &t, &kin, &cfg, &bl), 0);
    }
    lines.truncate(0);
}
