//! The same programs streamed (`nc_plan::stream::Source`: parser, builder, planner and cutter a
//! line at a time, the planner dropping what it has committed): the stream refuses what the
//! whole pipeline refuses, no later in the program; otherwise it gives the whole plan's very
//! chunks, none planned above the machine's speed cap. Half the accepted programs then go
//! through the follower on the streamed chunks (their hold scaled by the cap and the margins'
//! ceiling, as `dnurbs run` streams them) instead of the whole plan's.
#![allow(clippy::vec_box)]

use nc_follow::{stop_length, Chunk, Start};
use nc_geom::kinematics::MachineKinematics;
use nc_geom::segment::{BuildLimits, Path};
use nc_lang::{Entries, Setup, StrLines};
use nc_plan::config::PlanConfig;
use nc_plan::profile::FeedProfile;
use nc_plan::stream::{cut, Machine, Source, StreamError};
use proptest::prelude::*;

/// Queue depth the streamed chunks are cut for.
pub const DEPTH: usize = 64;

/// A streamed program: its start and chunks.
pub type Streamed = (Start, Vec<Box<Chunk>>);

pub fn stream(
    src: &str,
    cfg: &PlanConfig,
    bl: &BuildLimits,
    kin: &MachineKinematics,
) -> Result<Streamed, StreamError> {
    let setup = Setup::default();
    let machine = Machine {
        kin,
        build: bl,
        plan: cfg,
    };
    let mut source = Source::new(Entries::new(StrLines::new(src), &setup), machine, DEPTH);
    let mut out = Vec::new();
    while let Some(c) = source.next_chunk()? {
        out.push(c);
    }
    let start = source
        .start()
        .expect("a streamed program that ended has a start");
    Ok((start, out))
}

/// The whole pipeline refused at `line`: the stream refused too, no later.
pub fn refused_too(
    s: &Result<Streamed, StreamError>,
    line: u32,
    src: &str,
) -> Result<(), TestCaseError> {
    match s {
        Err(e) => {
            prop_assert!(
                e.pos().line <= line,
                "streamed: {e}, whole: line {line}\n{src}"
            );
            Ok(())
        }
        Ok(_) => Err(TestCaseError::fail(format!(
            "the stream accepts what the whole pipeline refuses at line {line}\n{src}"
        ))),
    }
}

/// The whole pipeline accepted `path` with `profile`: the stream gives its chunks.
pub fn same_chunks(
    s: &Result<Streamed, StreamError>,
    path: &Path,
    profile: &FeedProfile,
    cfg: &PlanConfig,
    bl: &BuildLimits,
    src: &str,
) -> Result<(), TestCaseError> {
    let (start, streamed) = match s {
        Ok(s) => s,
        Err(e) => {
            return Err(TestCaseError::fail(format!(
                "the stream refuses what the whole pipeline accepts: {e}\n{src}"
            )))
        }
    };
    let cap = bl.speed_cap() * (1.0 + 1e-6);
    let len = stop_length(cap, &nc_plan::verify::ceiling(cfg), &cfg.hold(), DEPTH);
    let (whole_start, whole) = cut(path.clone(), profile, len);
    prop_assert_eq!(start.empty, whole_start.empty);
    prop_assert_eq!(start.joints, whole_start.joints);
    prop_assert_eq!(streamed.len(), whole.len(), "chunks\n{}", src);
    for (a, b) in streamed.iter().zip(&whole) {
        prop_assert!(
            a.segments == b.segments
                && a.starts == b.starts
                && (a.s0, a.s1, a.t_start, a.t_end, a.t_arrive)
                    == (b.s0, b.s1, b.t_start, b.t_end, b.t_arrive)
                && a.phases == b.phases
                && (a.vmax, a.rests_at_end, a.last) == (b.vmax, b.rests_at_end, b.last),
            "chunk {} streamed otherwise\n{}",
            a.index,
            src
        );
        prop_assert!(
            a.vmax <= cap,
            "chunk {} at {} over the cap {}\n{}",
            a.index,
            a.vmax,
            cap,
            src
        );
    }
    Ok(())
}
