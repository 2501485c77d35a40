//! `ohaca ros --gif FILE` / `--png FILE`: the plans to one goal as a replanning drive
//! ([`Drive`]), drawn as an animated GIF ([`crate::strip::save_gif`]) or a strip of panels
//! ([`crate::strip::save_strip`]) after every plan, in the backend's cells: the map
//! each plan saw, the cells the updates before it changed, the plan, and the robot's trail from
//! one plan's start to the next along the plan it followed. A new goal (or map) starts a new
//! drive.

use std::path::PathBuf;

use ohaca::Point;

use crate::map::Map;
use crate::replan::{Drive, Planned, Step};
use crate::strip::{save_gif, save_strip, StripError};

/// See the module docs.
pub struct Recorder {
    gif: Option<PathBuf>,
    png: Option<PathBuf>,
    goal: Option<Point>,
    steps: Vec<Step>,
    /// Cells blocked by updates since the last plan.
    blocked: Vec<Point>,
    /// Cells cleared since the last plan.
    cleared: Vec<Point>,
}

impl Recorder {
    /// Record into a GIF, a PNG strip or both.
    pub fn new(gif: Option<PathBuf>, png: Option<PathBuf>) -> Self {
        Recorder {
            gif,
            png,
            goal: None,
            steps: Vec::new(),
            blocked: Vec::new(),
            cleared: Vec::new(),
        }
    }

    /// A new map: a new drive.
    pub fn new_map(&mut self) {
        self.goal = None;
        self.steps.clear();
        self.blocked.clear();
        self.cleared.clear();
    }

    /// Cells an update changed (backend cells).
    pub fn changed(&mut self, blocked: &[Point], cleared: &[Point]) {
        self.blocked.extend_from_slice(blocked);
        self.cleared.extend_from_slice(cleared);
    }

    /// A plan from `start` to `goal` (backend cells) on `map`; the GIF is drawn again.
    pub fn plan(
        &mut self,
        map: &Map,
        (start, goal): (Point, Point),
        plan: &Planned,
    ) -> Result<(), StripError> {
        if self.goal != Some(goal)
            || self
                .steps
                .last()
                .is_some_and(|s| (s.map.width, s.map.height) != (map.width, map.height))
        {
            self.steps.clear();
            self.goal = Some(goal);
        }
        let (changed, blocked) = if self.blocked.is_empty() {
            (std::mem::take(&mut self.cleared), false)
        } else {
            self.cleared.clear();
            (std::mem::take(&mut self.blocked), true)
        };
        self.steps.push(Step {
            robot: start,
            at: 0,
            changed,
            blocked,
            map: map.clone(),
            plan: plan.clone(),
            optimum: None,
        });
        let drive = self.drive();
        if let Some(p) = &self.gif {
            save_gif(&drive, goal, p)?;
        }
        if let Some(p) = &self.png {
            save_strip(&drive, goal, p)?;
        }
        Ok(())
    }

    /// The drive so far: each plan followed up to the next plan's start.
    fn drive(&self) -> Drive {
        let mut trail: Vec<Point> = Vec::new();
        let mut steps = self.steps.clone();
        for k in 0..steps.len() {
            let robot = steps.get(k).map_or(Point::new(0, 0), |s| s.robot);
            if trail.last() != Some(&robot) {
                let prev = k.checked_sub(1).and_then(|j| steps.get(j));
                let on = prev.and_then(|p| p.plan.raw.iter().position(|&c| c == robot));
                match (prev, on) {
                    (Some(p), Some(i)) => trail.extend(p.plan.raw.iter().take(i + 1).skip(1)),
                    _ => trail.push(robot),
                }
            }
            if let Some(s) = steps.get_mut(k) {
                s.at = trail.len().saturating_sub(1);
            }
        }
        if let Some(last) = steps.last() {
            trail.extend(last.plan.raw.iter().skip(1));
        }
        Drive { steps, trail }
    }
}
