//! Pictures of a replanning drive ([`crate::replan::Drive`]): a strip of PNG panels, one per plan,
//! and an animated GIF of the robot driving.
//!
//! Colours: free cells white, obstacles dark grey, cells blocked by a change red, cells cleared
//! by one green; the robot's trail blue, the plan it follows orange (raw path light, smoothed
//! waypoints dark), the plan it dropped light grey; the robot a blue square, the goal a black one.
//! A bar across the top of each panel says what answered the plan: grey a cold run, orange a
//! warm run (the colony kept), teal the rest of the last answer (reused, no run),
//! purple the rest with a local detour (repaired, no run).

use std::path::{Path, PathBuf};

use image::codecs::gif::{GifEncoder, Repeat};
use image::{Delay, Frame, Rgb, RgbImage, RgbaImage};

use crate::map::Map;
use crate::replan::Drive;
use ohaca::Point;

const FREE: Rgb<u8> = Rgb([255, 255, 255]);
const WALL: Rgb<u8> = Rgb([60, 60, 60]);
const ADDED: Rgb<u8> = Rgb([220, 30, 30]);
const CLEARED: Rgb<u8> = Rgb([40, 180, 60]);
const TRAIL: Rgb<u8> = Rgb([30, 90, 220]);
const RAW: Rgb<u8> = Rgb([250, 190, 120]);
const SMOOTH: Rgb<u8> = Rgb([230, 110, 0]);
const OLD: Rgb<u8> = Rgb([190, 190, 190]);
const GOAL: Rgb<u8> = Rgb([0, 0, 0]);
const GAP: u32 = 8;
const MARK_COLD: Rgb<u8> = Rgb([120, 120, 120]);
const MARK_WARM: Rgb<u8> = Rgb([250, 150, 0]);
const MARK_REUSED: Rgb<u8> = Rgb([0, 160, 170]);
const MARK_REPAIRED: Rgb<u8> = Rgb([150, 60, 200]);

/// The bar's colour for a plan's origin.
pub fn mark(origin: ohaca::planner::Origin) -> Rgb<u8> {
    match origin {
        ohaca::planner::Origin::Cold => MARK_COLD,
        ohaca::planner::Origin::Warm => MARK_WARM,
        ohaca::planner::Origin::Reused => MARK_REUSED,
        ohaca::planner::Origin::Repaired => MARK_REPAIRED,
    }
}

/// Pixels per cell: the map fills about 512 pixels on its longer side.
fn scale(map: &Map) -> u32 {
    (512 / u32::from(map.width.max(map.height)).max(1)).clamp(1, 24)
}

struct Canvas {
    img: RgbImage,
    s: u32,
    x0: u32,
}

/// Pixels of the bar above each panel that says what answered its plan.
const BAR: u32 = 8;

impl Canvas {
    fn cell(&mut self, p: Point, c: Rgb<u8>) {
        for dy in 0..self.s {
            for dx in 0..self.s {
                let (x, y) = (
                    self.x0 + u32::from(p.x) * self.s + dx,
                    BAR + u32::from(p.y) * self.s + dy,
                );
                if x < self.img.width() && y < self.img.height() {
                    self.img.put_pixel(x, y, c);
                }
            }
        }
    }

    /// A dot of `r` pixels around the centre of cell `p`.
    fn dot(&mut self, p: Point, r: i64, c: Rgb<u8>) {
        let (cx, cy) = self.centre(p);
        for y in cy - r..=cy + r {
            for x in cx - r..=cx + r {
                self.pixel(x, y, c);
            }
        }
    }

    fn centre(&self, p: Point) -> (i64, i64) {
        let s = i64::from(self.s);
        (
            i64::from(self.x0) + i64::from(p.x) * s + s / 2,
            i64::from(BAR) + i64::from(p.y) * s + s / 2,
        )
    }

    fn pixel(&mut self, x: i64, y: i64, c: Rgb<u8>) {
        if x >= i64::from(self.x0) && y >= 0 {
            let (x, y) = (x as u32, y as u32);
            if x < self.img.width() && y < self.img.height() {
                self.img.put_pixel(x, y, c);
            }
        }
    }

    /// A polyline through cell centres, `w` pixels wide.
    fn line(&mut self, pts: &[Point], w: i64, c: Rgb<u8>) {
        for (&p, &q) in pts.iter().zip(pts.iter().skip(1)) {
            let (a, b) = (self.centre(p), self.centre(q));
            let n = (b.0 - a.0).abs().max((b.1 - a.1).abs()).max(1);
            for i in 0..=n {
                let x = a.0 + (b.0 - a.0) * i / n;
                let y = a.1 + (b.1 - a.1) * i / n;
                for oy in -(w / 2)..=(w - 1) / 2 {
                    for ox in -(w / 2)..=(w - 1) / 2 {
                        self.pixel(x + ox, y + oy, c);
                    }
                }
            }
        }
    }

    fn map(&mut self, map: &Map) {
        for y in 0..map.height {
            for x in 0..map.width {
                let p = Point::new(x, y);
                self.cell(p, if map.is_blocked(p) { WALL } else { FREE });
            }
        }
    }
}

/// Where the robot is on the drive's trail at each plan.
fn plan_positions(drive: &Drive) -> Vec<usize> {
    drive.steps.iter().map(|s| s.at).collect()
}

/// Draw the picture of the drive at trail index `t` (plan `k` active) onto `c`.
fn scene(c: &mut Canvas, drive: &Drive, at: &[usize], k: usize, t: usize, goal: Point) {
    let (Some(step), Some(&here)) = (drive.steps.get(k), at.get(k)) else {
        return;
    };
    c.map(&step.map);
    let w = i64::from((c.s / 3).max(1));
    let r = i64::from((c.s / 2).max(2));
    for s in drive.steps.iter().take(k + 1) {
        for &p in &s.changed {
            // A little larger than a cell, so a one-cell wall shows on a 1000-cell map.
            c.dot(p, r, if s.blocked { ADDED } else { CLEARED });
        }
    }
    if t == here && k > 0 {
        // The moment of the replan: the plan it drops.
        if let (Some(prev), Some(&there)) = (drive.steps.get(k - 1), at.get(k - 1)) {
            let from = t.saturating_sub(there);
            c.line(prev.plan.raw.get(from..).unwrap_or(&[]), w, OLD);
        }
    }
    let from = t.saturating_sub(here);
    c.line(step.plan.raw.get(from..).unwrap_or(&[]), w, RAW);
    if from == 0 {
        c.line(&step.plan.waypoints, w + 1, SMOOTH);
    }
    c.line(drive.trail.get(..=t).unwrap_or(&[]), w + 1, TRAIL);
    c.dot(goal, r, GOAL);
    if let Some(&p) = drive.trail.get(t) {
        c.dot(p, r, TRAIL);
    }
    // What answered this plan: the bar above the panel.
    let pw = i64::from(step.map.width) * i64::from(c.s);
    let x0 = i64::from(c.x0);
    for y in 0..i64::from(BAR) - 2 {
        for x in x0..x0 + pw {
            c.pixel(x, y, mark(step.plan.origin));
        }
    }
}

/// A strip of panels, one per plan, at the moment the robot planned it.
pub fn strip(drive: &Drive, goal: Point) -> Result<RgbImage, StripError> {
    let first = drive.steps.first().ok_or(StripError::NoPlans)?;
    let s = scale(&first.map);
    let (pw, ph) = (
        u32::from(first.map.width) * s,
        u32::from(first.map.height) * s,
    );
    let n = drive.steps.len() as u32;
    let mut c = Canvas {
        img: RgbImage::from_pixel(n * pw + (n - 1) * GAP, BAR + ph, Rgb([255, 255, 255])),
        s,
        x0: 0,
    };
    let at = plan_positions(drive);
    for (k, &t) in at.iter().enumerate() {
        c.x0 = k as u32 * (pw + GAP);
        scene(&mut c, drive, &at, k, t, goal);
    }
    Ok(c.img)
}

/// Save [`strip`] as a PNG.
pub fn save_strip(drive: &Drive, goal: Point, path: &Path) -> Result<(), StripError> {
    strip(drive, goal)?
        .save(path)
        .map_err(|error| StripError::Image {
            path: path.to_path_buf(),
            error,
        })
}

/// Why a picture of a drive cannot be made.
#[derive(Debug, thiserror::Error)]
pub enum StripError {
    /// The drive has no plan.
    #[error("no plans to draw")]
    NoPlans,
    /// The file cannot be created.
    #[error("{}: {error}", .path.display())]
    Create {
        /// The file.
        path: PathBuf,
        /// The system's error.
        error: std::io::Error,
    },
    /// The image cannot be encoded or written.
    #[error("{}: {error}", .path.display())]
    Image {
        /// The file.
        path: PathBuf,
        /// The encoder's error.
        error: image::ImageError,
    },
}

/// An animated GIF of the robot driving: about 60 frames, a pause at every replan.
pub fn save_gif(drive: &Drive, goal: Point, path: &Path) -> Result<(), StripError> {
    let first = drive.steps.first().ok_or(StripError::NoPlans)?;
    let s = scale(&first.map).min(4);
    let (pw, ph) = (
        u32::from(first.map.width) * s,
        u32::from(first.map.height) * s,
    );
    let at = plan_positions(drive);
    let stride = (drive.trail.len() / 60).max(1);
    let mut times: Vec<usize> = (0..drive.trail.len()).step_by(stride).collect();
    times.extend(at.iter().copied());
    times.push(drive.trail.len().saturating_sub(1));
    times.sort_unstable();
    times.dedup();
    let file = std::fs::File::create(path).map_err(|error| StripError::Create {
        path: path.to_path_buf(),
        error,
    })?;
    let image = |error| StripError::Image {
        path: path.to_path_buf(),
        error,
    };
    let mut enc = GifEncoder::new_with_speed(std::io::BufWriter::new(file), 20);
    enc.set_repeat(Repeat::Infinite).map_err(image)?;
    for &t in &times {
        let k = at.iter().rposition(|&a| a <= t).unwrap_or(0);
        let mut c = Canvas {
            img: RgbImage::from_pixel(pw, BAR + ph, FREE),
            s,
            x0: 0,
        };
        scene(&mut c, drive, &at, k, t, goal);
        let pause = if at.contains(&t) || t + 1 == drive.trail.len() {
            900
        } else {
            80
        };
        let rgba: RgbaImage = image::DynamicImage::ImageRgb8(c.img).to_rgba8();
        enc.encode_frame(Frame::from_parts(
            rgba,
            0,
            0,
            Delay::from_numer_denom_ms(pause, 1),
        ))
        .map_err(image)?;
    }
    Ok(())
}
