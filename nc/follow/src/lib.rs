//! Streaming: planned segments handed from the non-real-time planner thread to the real-time
//! interpolator through preallocated `heapless` SPSC queues, with feed hold.
//!
//! The planner plans the feed (in windows of bounded look-ahead, `nc_plan::plan`) and cuts
//! the result into [`Chunk`]s: a run of consecutive segments with their arc-length tables
//! and the profile phases that cover them. Chunks travel as `Box`es, so a queue moves
//! pointers: the real-time side allocates nothing and frees nothing. A second queue carries
//! consumed chunks back to the planner thread, which frees them. The planner keeps at most
//! `depth` chunks alive (in the queues or held by the interpolator); `depth` comes from the
//! machine file.
//!
//! **Look-ahead in distance.** The interpolator holds at most `depth` chunks (and at most
//! [`LOOKAHEAD`]), so a chunk is cut at least [`chunk_length`] long: the distance to stop
//! from the plan's top speed, shared out over the chunks held, with a quarter to spare.
//! Whatever the programmed moves' length (a CAM program of 0.05 mm moves, or shorter), the
//! path that has arrived then covers a stop, and a planner that keeps up never makes the
//! tool hold.
//!
//! **Feed hold.** The interpolator follows the plan in plan time `tau`, advanced by
//! `k * Ts` each period. The override `k` in [0, 1] is driven by a rate- and jerk-limited
//! tracker toward 1, or toward 0 when the path that has arrived ends within the distance
//! needed to stop (an underrun: the planner fell behind), or when a stop is requested
//! (SIGINT, a fault), or toward the operator's override (0 while paused). Geometry is
//! untouched, so the tool slows along the path and stops on it, then resumes the plan where
//! it left off; the position never jumps. The tracker's rate is limited to `hold_acc / v`
//! and its rate of change to `hold_jerk / v`, with `v` the highest planned speed from the
//! chunk at hand to the program's end ([`Chunk::vmax_ahead`]), so holding adds at most
//! `hold_acc` of path acceleration and `hold_jerk` of path jerk to the plan's own. `v` never
//! rises while the tool moves on, so neither path limit ever tightens under a hold in
//! progress (the axes' bounds below tighten as k rises, and are met by braking ahead).
//!
//! **Every axis's acceleration holds during a hold.** With the plan's joint trajectory
//! q(tau) and tau advancing at the rate k, an axis moves at `k q'` and accelerates at
//! `k^2 q'' + k' q'` (primes: derivatives in plan time). The plan's own check measured
//! `|q''| <= f A` and `|q'| <= w` for each axis (its margins, with `f <= 1 - HOLD_RESERVE`),
//! so the axis stays within its acceleration limit A as long as
//! `|k'| <= A (1 - f k^2) / w`. The tracker's rate is held under the least of these over
//! the axes (times [`HOLD_SHARE`], for the discretisation), evaluated at the highest k the
//! period can reach: the bound grows as k falls, so a stop can always begin (f < 1) and then
//! slows down faster and faster; a resume eases into the plan as k nears 1.
//!
//! **And every axis's jerk.** The axis's jerk is `k^3 q''' + 3 k k' q'' + k'' q'`. The
//! plan's check measured `|q'''| <= p` (its jerk margin; a plan keeps
//! `nc_geom::limits::JERK_RESERVE` of the limit J), so a hold may spend
//! `B(k) = s J - p k^3` (s is [`HOLD_JERK_SHARE`]): half on the rate,
//! `|k'| <= B / (6 k a)` (a = f A, the plan's acceleration), half on the rate's change,
//! `|k''| <= B / (2 w)`. Both bounds grow as k falls: a stop may change its rate faster as
//! it slows down. A resume, whose bounds tighten as k rises, takes its rate's bound where
//! k will be once the rate is braked at the bound for k = 1, and brakes toward its target
//! at what the target allows, so that the bound never falls under the rate. The plan time
//! a period covers is the integral of k, quadratic within it; a target is taken at once
//! only at a rate that one step of k'' ends. And `nc_plan::verify` measures the plan's
//! jerk between its own phases where it changes fast: a hold shifts the phase at which
//! the drives' setpoints meet the plan.
#![forbid(unsafe_code)]

mod chunk;
mod follower;
mod gates;
mod hold;
pub mod jog;
pub mod jog_line;
mod queue;
mod stop;
mod tracker;

pub use chunk::{phase_vmax, Chunk, Start, MAX_CHUNK_SEGMENTS, REST_V};
pub use follower::{Follower, StreamCounters};
pub use hold::{HoldConfig, HOLD_JERK_SHARE, HOLD_SHARE};
pub use queue::{Feeder, Inlet, Queues, LOOKAHEAD, MAX_DEPTH, MIN_DEPTH, QUEUE_N};
pub use stop::stop_length;
