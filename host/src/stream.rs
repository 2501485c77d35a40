//! A robot's costmap stream: map updates at a fixed rate while the robot drives, each followed by
//! a replan, as `ohaca ros` does on every `/map_updates` message of a Nav2 costmap.
//!
//! The simulated costmap is what a robot's sensors make of people and boxes: small obstacles (1
//! to 3 cells) that appear and go away again. Each update either removes one of the obstacles it
//! placed before (half the time, when there is one) or places a new one, and a new one lies on or
//! next to the rest of the robot's path (within one cell of a path cell 3 to 40 cells ahead) with
//! probability [`Stream::near`], anywhere free on the map otherwise. Between two updates the robot
//! drives `speed / hz` cells along its current path; after each update it replans from its cell
//! (warm, `PlanWarm`, or cold). Every answer is checked on the map as it was when it was asked
//! ([`crate::replan::check`]) and measured against the exact optimum, as in a scenario drive.
//!
//! Deterministic: the generator is seeded ([`Stream::seed`]), and the changes depend only on the
//! map and on the paths, so the host core and a device that answer alike see the same stream.
//!
//! The cost figure that matters on a board is the share of its time spent planning:
//! [`Summary::busy`], the device's instructions over all replans divided by what a core at
//! `clock_hz` executes in the stream's duration (`updates / hz` seconds).

use ohaca::Point;

use crate::map::Map;
use crate::replan::{plan_step, set_cell, Drive, Planner, ReplanError, Step};
use crate::rng::Rng;

/// How the stream runs. See the module docs.
#[derive(Clone, Copy, Debug)]
pub struct Stream {
    /// Map updates (each followed by a replan).
    pub updates: usize,
    /// Updates a second.
    pub hz: f64,
    /// The robot's speed, cells a second.
    pub speed: f64,
    /// Share of new obstacles on or next to the path, `0..=1`.
    pub near: f64,
    /// Seed of the changes.
    pub seed: u64,
}

impl Default for Stream {
    /// 100 updates at 5 Hz, a robot at 10 cells a second (0.5 m/s on a 5 cm map), one new
    /// obstacle in ten on or next to the path, seed 1.
    fn default() -> Self {
        Stream {
            updates: 100,
            hz: 5.0,
            speed: 10.0,
            near: 0.1,
            seed: 1,
        }
    }
}

/// Drive `map` from `start` to `goal` under the stream `s`, replanning with `planner` after every
/// update (warm when `warm`). Stops early when the robot is one cell from the goal.
pub fn stream(
    s: &Stream,
    map: &Map,
    (start, goal): (Point, Point),
    planner: &mut dyn Planner,
    warm: bool,
) -> Result<Drive, ReplanError> {
    if !(s.hz > 0.0 && s.speed > 0.0 && (0.0..=1.0).contains(&s.near)) {
        return Err(ReplanError::BadStream);
    }
    let mut map = map.clone();
    let mut rng = Rng(s.seed);
    planner.set_map(&map)?;
    let mut robot = start;
    let mut trail = vec![start];
    let mut steps: Vec<Step> = vec![plan_step(
        planner,
        (robot, 0),
        goal,
        &map,
        Vec::new(),
        true,
        false,
    )?];
    let per = ((s.speed / s.hz).round() as usize).max(1);
    // The obstacles placed so far and still there.
    let mut live: Vec<Vec<Point>> = Vec::new();
    for k in 0..s.updates {
        let path = steps.last().map(|s| s.plan.raw.clone()).unwrap_or_default();
        if path.len() <= 2 {
            break; // arrived
        }
        let to = per.min(path.len() - 2);
        trail.extend(path.iter().skip(1).take(to));
        let (Some(&here), Some(ahead)) = (path.get(to), path.get(to..)) else {
            break;
        };
        robot = here;
        let (cells, blocked) = if !live.is_empty() && rng.unit() < 0.5 {
            let i = rng.below(live.len());
            // Leave the robot's own cell alone (it drove onto a cell an obstacle left).
            (live.swap_remove(i), false)
        } else {
            let near = rng.unit() < s.near;
            let blob = obstacle(&map, &mut rng, ahead, near, robot, goal);
            if !blob.is_empty() {
                live.push(blob.clone());
            }
            (blob, true)
        };
        let cells: Vec<Point> = cells.into_iter().filter(|&p| p != robot).collect();
        for &p in &cells {
            set_cell(&mut map, p, blocked)?;
        }
        planner
            .change(&cells, blocked)
            .map_err(|e| e.at_update(k))?;
        let at = trail.len() - 1;
        let step = plan_step(planner, (robot, at), goal, &map, cells, blocked, warm)
            .map_err(|e| e.at_update(k))?;
        steps.push(step);
    }
    if let Some(last) = steps.last() {
        trail.extend(last.plan.raw.iter().skip(1));
    }
    Ok(Drive { steps, trail })
}

/// A new obstacle of 1 to 3 free cells: on or next to `ahead` (3 to 40 cells ahead) when `near`,
/// else anywhere; never on the robot's cell or the goal. Empty when 64 tries found no room.
fn obstacle(
    map: &Map,
    rng: &mut Rng,
    ahead: &[Point],
    near: bool,
    robot: Point,
    goal: Point,
) -> Vec<Point> {
    let free = |x: i64, y: i64| {
        (x >= 0 && y >= 0 && x < i64::from(map.width) && y < i64::from(map.height))
            .then(|| Point::new(x as u16, y as u16))
            .filter(|&p| !map.is_blocked(p) && p != robot && p != goal)
    };
    for _ in 0..64 {
        let centre = if near {
            let last = ahead.len().saturating_sub(1);
            let (lo, hi) = (3.min(last), 40.min(last));
            let c = ahead.get(lo + rng.below(hi - lo + 1)).copied();
            let (dx, dy) = (rng.below(3) as i64 - 1, rng.below(3) as i64 - 1);
            c.and_then(|c| free(i64::from(c.x) + dx, i64::from(c.y) + dy))
        } else {
            let i = rng.below(map.cells());
            let w = usize::from(map.width);
            free((i % w) as i64, (i / w) as i64)
        };
        let Some(c) = centre else { continue };
        let mut blob = vec![c];
        for _ in 0..rng.below(3) {
            let (dx, dy) = (rng.below(3) as i64 - 1, rng.below(3) as i64 - 1);
            if let Some(p) = free(i64::from(c.x) + dx, i64::from(c.y) + dy) {
                if !blob.contains(&p) {
                    blob.push(p);
                }
            }
        }
        return blob;
    }
    Vec::new()
}

/// What a stream cost.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Summary {
    /// Replans (updates answered).
    pub replans: usize,
    /// Answers by kind: cold, warm, reused, repaired.
    pub cold: usize,
    /// See `cold`.
    pub warm: usize,
    /// See `cold`.
    pub reused: usize,
    /// See `cold`.
    pub repaired: usize,
    /// Device instructions over all replans (ticks x 1000 under `-icount shift=0`), if a device
    /// answered.
    pub instructions: Option<u64>,
    /// Ant moves over all replans.
    pub moves: u64,
    /// The stream's duration, seconds (`replans / hz`).
    pub seconds: f64,
    /// Share of a `clock_hz` core's time spent planning (`instructions / clock_hz / seconds`).
    pub busy: Option<f64>,
}

/// Count `d`'s replans (every plan after the first) for a stream at `hz` on a core at `clock_hz`.
pub fn summary(d: &Drive, hz: f64, clock_hz: f64) -> Summary {
    let replans = d.steps.get(1..).unwrap_or_default();
    let mut s = Summary {
        replans: replans.len(),
        seconds: replans.len() as f64 / hz,
        ..Summary::default()
    };
    let mut instructions = Some(0u64);
    for st in replans {
        match st.plan.origin {
            ohaca::planner::Origin::Cold => s.cold += 1,
            ohaca::planner::Origin::Warm => s.warm += 1,
            ohaca::planner::Origin::Reused => s.reused += 1,
            ohaca::planner::Origin::Repaired => s.repaired += 1,
        }
        s.moves += st.plan.moves;
        instructions = match (instructions, st.plan.ticks) {
            (Some(a), Some(t)) => Some(a + t * 1000),
            _ => None,
        };
    }
    s.instructions = instructions;
    s.busy = instructions
        .filter(|_| s.seconds > 0.0)
        .map(|i| i as f64 / clock_hz / s.seconds);
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::replan::HostPlanner;
    use ohaca::Params;

    fn city() -> Map {
        // 64 x 64: blocks of buildings with streets between.
        Map::from_fn(64, 64, |x, y| {
            x % 16 >= 3 && y % 16 >= 3 && x % 16 < 13 && y % 16 < 13
        })
    }

    #[test]
    fn the_stream_is_deterministic_and_every_answer_valid() {
        let s = Stream {
            updates: 40,
            ..Stream::default()
        };
        let ends = (Point::new(1, 1), Point::new(62, 62));
        let run = || {
            let mut p = HostPlanner::new(Params::default());
            stream(&s, &city(), ends, &mut p, true).unwrap()
        };
        let (a, b) = (run(), run());
        assert_eq!(a.steps.len(), b.steps.len());
        for (x, y) in a.steps.iter().zip(&b.steps) {
            assert_eq!(x.plan, y.plan);
            assert_eq!(x.changed, y.changed);
        }
        let sum = summary(&a, s.hz, 100e6);
        assert_eq!(sum.replans, a.steps.len() - 1);
        assert_eq!(sum.cold + sum.warm + sum.reused + sum.repaired, sum.replans);
        assert!(sum.reused > sum.replans / 2, "{sum:?}");
        assert!(
            sum.warm + sum.repaired > 0,
            "an obstacle on the path makes a run or a repair: {sum:?}"
        );
        assert_eq!(sum.instructions, None, "the host core has no ticks");
        // Cold: every answer a run.
        let mut p = HostPlanner::new(Params::default());
        let c = stream(&s, &city(), ends, &mut p, false).unwrap();
        assert_eq!(summary(&c, s.hz, 100e6).cold, c.steps.len() - 1);
    }
}
