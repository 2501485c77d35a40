//! Pictures for people: a map with planned paths ([`Scene`]) and a convergence chart
//! ([`Convergence`]), drawn with `plotters` into SVG or PNG.
//!
//! The same drawing code runs on both backends ([`Picture::draw`] is generic over the backend);
//! [`save`] picks the format from the file name (`.svg` or `.png`). PNGs are drawn into an RGB
//! buffer and encoded with the `image` crate, so nothing depends on the machine: text is set in
//! the Go font, vendored in `host/assets/` (BSD licence beside it) and registered with plotters
//! at first use. SVGs carry the same font as a `data:` URL in an `@font-face` rule
//! ([`embed_font`]), so browsers set their text in it whatever fonts the machine has. Output is a
//! pure function of the input (no timestamps, no thread-dependent order).
//!
//! ## The map picture
//! Free cells white, obstacles dark grey, optionally the final pheromone as a purple heat map
//! under everything (log scale, per cell the strongest of its 8 edges). Each algorithm's raw ant
//! path is a thin line through cell centres; its output path (smoothed for OHACA, the raw path's
//! corners otherwise) a thick line with a dot per waypoint. With several algorithms the lines get
//! narrower in order, so shared segments show every colour. Start: green disc `S`; goal: black
//! disc `G`. A legend on the right gives each algorithm's numbers.

use std::path::{Path, PathBuf};
use std::sync::Once;

use ohaca::{Algorithm, Point};
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

/// The vendored font (Go Regular, BSD licence: `host/assets/LICENSE-Go-fonts.txt`).
const FONT: &[u8] = include_bytes!("../assets/Go-Regular.ttf");
/// The family name every text style uses.
const FAMILY: &str = "sans-serif";

static FONT_ONCE: Once = Once::new();

/// Register the vendored font with plotters (idempotent).
pub fn register_font() {
    FONT_ONCE.call_once(|| {
        // The font is a valid TTF compiled into the binary; a failure would only mean text
        // cannot be measured, which the drawing reports as an error.
        let _ = plotters::style::register_font(FAMILY, FontStyle::Normal, FONT);
    });
}

/// A colour as `0xRRGGBB`.
pub const fn rgb(c: u32) -> RGBColor {
    RGBColor((c >> 16) as u8, (c >> 8) as u8, c as u8)
}

/// The colour of an algorithm's paths (Okabe-Ito palette, colour-blind safe).
pub const fn algorithm_colour(a: Algorithm) -> RGBColor {
    match a {
        Algorithm::Aca => rgb(0xE6_9F_00),
        Algorithm::Paca => rgb(0x56_B4_E9),
        Algorithm::Haca => rgb(0x00_72_B2),
        Algorithm::Ohaca => rgb(0xD5_5E_00),
    }
}

/// Upper-case display name of an algorithm.
pub fn display_name(a: Algorithm) -> String {
    a.name().to_ascii_uppercase()
}

/// Free cells.
pub const FREE: RGBColor = RGBColor(255, 255, 255);
/// Obstacles.
pub const BLOCKED: RGBColor = RGBColor(0x50, 0x50, 0x50);
/// Cell borders.
pub const GRID: RGBColor = RGBColor(0xE4, 0xE4, 0xE4);
/// The start marker.
pub const START: RGBColor = RGBColor(0x00, 0x9E, 0x73);
/// The goal marker.
pub const GOAL: RGBColor = RGBColor(0, 0, 0);
/// Text.
pub const INK: RGBColor = RGBColor(0x20, 0x20, 0x20);
/// Secondary text.
pub const MUTED: RGBColor = RGBColor(0x60, 0x60, 0x60);

/// Heat-map colour for `t` in `[0, 1]`: white to deep purple.
pub fn heat(t: f64) -> RGBColor {
    let t = if t.is_finite() {
        t.clamp(0.0, 1.0)
    } else {
        0.0
    };
    // White -> #BCBDDC -> #54278F.
    let stops = [
        (255.0, 255.0, 255.0),
        (188.0, 189.0, 220.0),
        (84.0, 39.0, 143.0),
    ];
    let (a, b, u) = if t < 0.5 {
        (stops[0], stops[1], t * 2.0)
    } else {
        (stops[1], stops[2], (t - 0.5) * 2.0)
    };
    let mix = |x: f64, y: f64| (x + (y - x) * u).round().clamp(0.0, 255.0) as u8;
    RGBColor(mix(a.0, b.0), mix(a.1, b.1), mix(a.2, b.2))
}

/// Something that can be drawn on any plotters backend.
pub trait Picture {
    /// Width and height in pixels.
    fn size(&self) -> (u32, u32);
    /// Draw on `area` (of [`Picture::size`]).
    fn draw<DB: DrawingBackend>(&self, area: &DrawingArea<DB, Shift>) -> Result<(), DrawError>;
}

/// The picture as an SVG document, with the font embedded (see [`embed_font`]).
pub fn to_svg<P: Picture>(p: &P) -> Result<String, DrawError> {
    register_font();
    let mut s = String::new();
    {
        let root = SVGBackend::with_string(&mut s, p.size()).into_drawing_area();
        p.draw(&root)?;
        root.present().map_err(err)?;
    }
    Ok(embed_font(&s))
}

/// The family name of the font embedded in SVGs.
pub const SVG_FAMILY: &str = "OhacaGo";

/// Embed the vendored font in an SVG document drawn by plotters: an `@font-face` rule whose
/// source is the TTF itself as a `data:` URL, and every `font-family="sans-serif"` attribute
/// turned into `"OhacaGo, sans-serif"`. A viewer with CSS fonts (every browser, also for an SVG
/// shown through `<img>`) then sets the text in the same font as the PNGs, whatever fonts the
/// machine has; one without them (e.g. librsvg) falls back to its own sans-serif.
pub fn embed_font(svg: &str) -> String {
    let style = format!(
        "<defs><style>@font-face{{font-family:\"{SVG_FAMILY}\";\
         src:url(data:font/ttf;base64,{}) format(\"truetype\");}}</style></defs>",
        base64(FONT)
    );
    let family = format!("font-family=\"{SVG_FAMILY}, {FAMILY}\"");
    let body = svg.replace(&format!("font-family=\"{FAMILY}\""), &family);
    // After the opening tag `<svg ...>`.
    match body
        .find("<svg")
        .and_then(|i| body.get(i..)?.find('>').map(|j| i + j + 1))
    {
        Some(at) => {
            let (head, tail) = body.split_at(at);
            format!("{head}\n{style}{tail}")
        }
        None => body,
    }
}

/// Standard base64 (RFC 4648, with `=` padding).
pub fn base64(bytes: &[u8]) -> String {
    use base64::Engine as _;
    base64::engine::general_purpose::STANDARD.encode(bytes)
}

/// Width in pixels of `text` set in the vendored font at `size` (as the PNGs draw it).
pub fn text_width(text: &str, size: f64) -> u32 {
    register_font();
    (FAMILY, size).into_font().box_size(text).map_or_else(
        // Only if the font could not be read: a generous estimate.
        |_| (text.chars().count() as f64 * size * 0.62).ceil() as u32,
        |(w, _)| w,
    )
}

/// The picture as RGB pixels, row-major, 3 bytes a pixel.
pub fn to_rgb<P: Picture>(p: &P) -> Result<Vec<u8>, DrawError> {
    register_font();
    let (w, h) = p.size();
    let bytes = u64::from(w) * u64::from(h) * 3;
    // 1 GiB of pixels (a 18000 x 18000 picture) is plenty; beyond that, say so instead of
    // exhausting the memory. SVG has no such limit.
    let too_large = DrawError::TooLarge {
        width: w,
        height: h,
    };
    if bytes > 1 << 30 {
        return Err(too_large);
    }
    let len = usize::try_from(bytes).map_err(|_| too_large)?;
    let mut buf = vec![255u8; len];
    {
        let root = BitMapBackend::with_buffer(&mut buf, (w, h)).into_drawing_area();
        p.draw(&root)?;
        root.present().map_err(err)?;
    }
    Ok(buf)
}

/// The picture as a PNG file's bytes.
pub fn to_png<P: Picture>(p: &P) -> Result<Vec<u8>, DrawError> {
    use image::ImageEncoder;
    let (w, h) = p.size();
    let rgb = to_rgb(p)?;
    let mut out = Vec::new();
    image::codecs::png::PngEncoder::new(&mut out)
        .write_image(&rgb, w, h, image::ExtendedColorType::Rgb8)
        .map_err(DrawError::Png)?;
    Ok(out)
}

/// The two picture formats.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// Scalable vector graphics.
    Svg,
    /// Portable network graphics.
    Png,
}

impl Format {
    /// The format a file name asks for (`.svg` or `.png`, any case).
    pub fn of(path: &Path) -> Option<Format> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        match ext.as_str() {
            "svg" => Some(Format::Svg),
            "png" => Some(Format::Png),
            _ => None,
        }
    }
}

/// Draw `p` into `path` (`.svg` or `.png`). The error is one line naming the file.
pub fn save<P: Picture>(p: &P, path: &Path) -> Result<(), DrawError> {
    let bytes = match Format::of(path) {
        Some(Format::Svg) => to_svg(p).map(String::into_bytes),
        Some(Format::Png) => to_png(p),
        None => return Err(DrawError::Extension(path.to_path_buf())),
    }
    .map_err(|e| DrawError::Draw {
        path: path.to_path_buf(),
        error: Box::new(e),
    })?;
    std::fs::write(path, bytes).map_err(|error| DrawError::Write {
        path: path.to_path_buf(),
        error,
    })
}

/// Why a picture cannot be drawn or saved.
#[derive(Debug, thiserror::Error)]
pub enum DrawError {
    /// The plotting library failed (its own words: its error type depends on the backend).
    #[error("{0}")]
    Plot(String),
    /// Too many pixels for a PNG.
    #[error("{width}x{height} pixels is too large for a PNG; write an SVG")]
    TooLarge {
        /// Pixels across.
        width: u32,
        /// Pixels down.
        height: u32,
    },
    /// The PNG encoder failed.
    #[error("cannot encode the PNG: {0}")]
    Png(image::ImageError),
    /// The file name asks for no format.
    #[error("{}: the picture's name must end in .svg or .png", .0.display())]
    Extension(PathBuf),
    /// Drawing the picture for a file failed.
    #[error("{}: cannot draw the picture: {error}", .path.display())]
    Draw {
        /// The file.
        path: PathBuf,
        /// What failed.
        error: Box<DrawError>,
    },
    /// The file cannot be written.
    #[error("{}: cannot write the file: {error}", .path.display())]
    Write {
        /// The file.
        path: PathBuf,
        /// The system's error.
        error: std::io::Error,
    },
}

/// A plotters error (whatever its backend) as a [`DrawError`].
fn err<E: std::fmt::Display>(e: E) -> DrawError {
    DrawError::Plot(e.to_string())
}

fn font(size: f64, colour: RGBColor) -> TextStyle<'static> {
    TextStyle {
        color: colour.to_backend_color(),
        ..TextStyle::from((FAMILY, size).into_font())
    }
}

fn left(style: TextStyle<'static>) -> TextStyle<'static> {
    style.pos(Pos::new(HPos::Left, VPos::Center))
}

fn centre(style: TextStyle<'static>) -> TextStyle<'static> {
    style.pos(Pos::new(HPos::Center, VPos::Center))
}

/// One algorithm's result to draw.
#[derive(Clone, Debug, PartialEq)]
pub struct Layer {
    /// The variant (gives the colour).
    pub algorithm: Algorithm,
    /// Raw ant path, `[x, y]` cells.
    pub raw: Vec<[u16; 2]>,
    /// Output waypoints.
    pub waypoints: Vec<[u16; 2]>,
    /// Legend text: first line (e.g. `length 36.657, 7 turns`), after the name.
    pub line1: String,
    /// Legend text: second line, smaller (may be empty).
    pub line2: String,
}

impl Layer {
    /// The layer of a report: output path length and turns on the first line; raw length, the
    /// iteration of the best path and the seed on the second (or why no path was found). With
    /// `resolution` (metres per cell) the output length is also given in metres.
    pub fn from_report(
        algorithm: Algorithm,
        r: &crate::output::PlanReport,
        resolution: Option<f64>,
    ) -> Layer {
        let turns = r.turns.map_or_else(
            || "- turns".to_string(),
            |t| crate::output::count(u64::from(t), "turn"),
        );
        let (line1, line2) = match (r.found, r.length, r.raw_length) {
            (true, Some(len), Some(raw)) => (
                match resolution {
                    Some(res) => format!("{:.2} m ({len:.3} cells), {turns}", f64::from(len) * res),
                    None => format!("length {len:.3}, {turns}"),
                },
                format!(
                    "raw {raw:.3}, best in iteration {}, seed {}",
                    r.best_iteration
                        .map_or_else(|| "-".to_string(), |b| (u32::from(b) + 1).to_string()),
                    r.params.seed
                ),
            ),
            _ => ("no path".to_string(), r.error.clone().unwrap_or_default()),
        };
        Layer {
            algorithm,
            raw: r.raw.clone(),
            waypoints: r.waypoints.clone(),
            line1,
            line2,
        }
    }
}

/// A map with paths: see the module docs.
#[derive(Clone, Debug, PartialEq)]
pub struct Scene {
    /// Title line.
    pub title: String,
    /// Second title line, smaller (may be empty).
    pub subtitle: String,
    /// The map.
    pub map: crate::map::Map,
    /// Start cell.
    pub start: Point,
    /// Goal cell.
    pub goal: Point,
    /// One layer per algorithm, drawn in order.
    pub layers: Vec<Layer>,
    /// Per-cell pheromone intensity (row-major, `width * height`), drawn as a heat map.
    pub pheromone: Option<Vec<f32>>,
    /// Legend text for the heat map (e.g. which algorithm's pheromone).
    pub pheromone_label: String,
    /// The map's metric frame, if any: the legend gives the start and goal in metres too.
    pub metric: Option<crate::map::MapFrame>,
}

/// Where a [`Scene`]'s parts go, in pixels. Public so tests can find a cell's pixels.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Layout {
    /// Pixels per cell side.
    pub cell: u32,
    /// Left edge of the map.
    pub map_x: u32,
    /// Top edge of the map.
    pub map_y: u32,
    /// Left edge of the legend.
    pub legend_x: u32,
    /// Picture width.
    pub width: u32,
    /// Picture height.
    pub height: u32,
}

const MARGIN: u32 = 16;
const TITLE_H: u32 = 52;
const LABEL_W: u32 = 34;
const LABEL_H: u32 = 18;
const LEGEND_W: u32 = 340;
const LEGEND_LINE: u32 = 22;
/// Legend text starts this far right of the legend's left edge (after the swatches).
const LEGEND_TEXT_DX: u32 = 44;
const TITLE_SIZE: f64 = 19.0;
const SUBTITLE_SIZE: f64 = 13.0;
const BODY_SIZE: f64 = 15.0;
const SMALL_SIZE: f64 = 13.0;

/// The first legend line of a layer: the algorithm's name and its numbers.
fn layer_line1(layer: &Layer) -> String {
    format!("{}: {}", display_name(layer.algorithm), layer.line1)
}

impl Layout {
    /// The layout of a `width x height` map with a legend of `legend_lines` lines.
    pub fn new(width: u16, height: u16, legend_lines: u32) -> Layout {
        let side = u32::from(width.max(height)).max(1);
        // About 800 pixels for the longer side, 2..=40 per cell; big maps get 1 pixel a cell.
        let cell = (800 / side).clamp(1, 40);
        let map_x = MARGIN + LABEL_W;
        let map_y = TITLE_H + LABEL_H;
        let map_w = u32::from(width) * cell;
        let map_h = u32::from(height) * cell;
        let legend_x = map_x + map_w + 2 * MARGIN;
        let legend_h = 2 * MARGIN + legend_lines * LEGEND_LINE;
        Layout {
            cell,
            map_x,
            map_y,
            legend_x,
            width: legend_x + LEGEND_W + MARGIN,
            height: (map_y + map_h + MARGIN).max(map_y + legend_h),
        }
    }

    /// Pixel of the centre of cell `(x, y)` (may lie outside the map for outside cells).
    pub fn centre(&self, x: u16, y: u16) -> (i32, i32) {
        let c = f64::from(self.cell);
        (
            (f64::from(self.map_x) + (f64::from(x) + 0.5) * c).floor() as i32,
            (f64::from(self.map_y) + (f64::from(y) + 0.5) * c).floor() as i32,
        )
    }

    /// Top-left pixel of cell `(x, y)`.
    pub fn corner(&self, x: u16, y: u16) -> (i32, i32) {
        (
            (self.map_x + u32::from(x) * self.cell) as i32,
            (self.map_y + u32::from(y) * self.cell) as i32,
        )
    }

    /// Width of the output path of layer `i` of `n`.
    pub fn path_width(&self, i: usize, n: usize) -> u32 {
        let base = (self.cell / 7).max(2);
        let step = (self.cell / 12).max(1);
        let rank = u32::try_from(n.saturating_sub(1).saturating_sub(i)).unwrap_or(0);
        base + rank * step
    }
}

impl Scene {
    /// Legend lines the scene needs.
    fn legend_lines(&self) -> u32 {
        let layers = u32::try_from(self.layers.len()).unwrap_or(u32::MAX / 4);
        // Header, 2 per layer, a gap, raw/output/waypoint keys, start, goal, obstacle, heat bar.
        1 + 2 * layers + 1 + 3 + 3 + u32::from(self.pheromone.is_some()) * 2
    }

    /// The scene's layout: [`Layout::new`], widened where a title or legend line would
    /// otherwise run off the right edge (small maps, long file names).
    pub fn layout(&self) -> Layout {
        let mut l = Layout::new(self.map.width, self.map.height, self.legend_lines());
        let text_x = l.legend_x + LEGEND_TEXT_DX;
        let mut lines: Vec<(u32, String, f64)> = vec![
            (MARGIN, self.title.clone(), TITLE_SIZE),
            (MARGIN, self.subtitle.clone(), SUBTITLE_SIZE),
            (text_x, self.pheromone_label.clone(), SMALL_SIZE),
        ];
        for layer in &self.layers {
            lines.push((text_x, layer_line1(layer), BODY_SIZE));
            lines.push((text_x, layer.line2.clone(), SMALL_SIZE));
        }
        for (label, p) in [("start", self.start), ("goal", self.goal)] {
            lines.push((text_x, self.endpoint_label(label, p), BODY_SIZE));
        }
        for (x, text, size) in lines {
            l.width = l.width.max(x + text_width(&text, size) + MARGIN);
        }
        l
    }

    /// The legend text of the start or the goal: the cell, and metres for maps with a frame.
    fn endpoint_label(&self, label: &str, p: Point) -> String {
        let metres = self.metric.map_or_else(String::new, |f| {
            let [mx, my] = f.to_metres(p);
            format!(" = ({mx:.2}, {my:.2}) m")
        });
        format!("{label} ({},{}){metres}", p.x, p.y)
    }

    fn draw_map<DB: DrawingBackend>(
        &self,
        a: &DrawingArea<DB, Shift>,
        l: &Layout,
    ) -> Result<(), DrawError> {
        let (w, h) = (self.map.width, self.map.height);
        let c = l.cell as i32;
        let (x0, y0) = l.corner(0, 0);
        let (x1, y1) = l.corner(w, h);
        a.draw(&Rectangle::new([(x0, y0), (x1, y1)], FREE.filled()))
            .map_err(err)?;
        // Heat map on free cells.
        if let Some(ph) = &self.pheromone {
            let free: Vec<f32> = ph
                .iter()
                .enumerate()
                .filter(|(i, v)| {
                    v.is_finite() && **v > 0.0 && !self.map.is_blocked(point_of(*i, w))
                })
                .map(|(_, v)| *v)
                .collect();
            let lo = free.iter().copied().fold(f32::INFINITY, f32::min);
            let hi = free.iter().copied().fold(0.0f32, f32::max);
            if hi > lo && lo > 0.0 {
                let span = f64::from(hi / lo).ln();
                for (i, v) in ph.iter().enumerate() {
                    let p = point_of(i, w);
                    if !v.is_finite() || *v <= 0.0 || self.map.is_blocked(p) {
                        continue;
                    }
                    let t = f64::from(*v / lo).ln() / span;
                    if t < 0.01 {
                        continue;
                    }
                    let (cx, cy) = l.corner(p.x, p.y);
                    a.draw(&Rectangle::new(
                        [(cx, cy), (cx + c, cy + c)],
                        heat(t).filled(),
                    ))
                    .map_err(err)?;
                }
            }
        }
        // Cell borders, when cells are big enough to see them.
        if l.cell >= 12 {
            let line = GRID.stroke_width(1);
            for x in 0..=w {
                let (px, _) = l.corner(x, 0);
                a.draw(&PathElement::new(vec![(px, y0), (px, y1)], line))
                    .map_err(err)?;
            }
            for y in 0..=h {
                let (_, py) = l.corner(0, y);
                a.draw(&PathElement::new(vec![(x0, py), (x1, py)], line))
                    .map_err(err)?;
            }
        }
        // Obstacles as horizontal runs.
        for y in 0..h {
            let mut x = 0u16;
            while x < w {
                if !self.map.is_blocked(Point::new(x, y)) {
                    x += 1;
                    continue;
                }
                let start = x;
                while x < w && self.map.is_blocked(Point::new(x, y)) {
                    x += 1;
                }
                let (ax, ay) = l.corner(start, y);
                let (bx, by) = l.corner(x, y + 1);
                a.draw(&Rectangle::new([(ax, ay), (bx, by)], BLOCKED.filled()))
                    .map_err(err)?;
            }
        }
        a.draw(&Rectangle::new(
            [(x0, y0), (x1, y1)],
            BLOCKED.stroke_width(1),
        ))
        .map_err(err)?;
        // Coordinates along the top and the left.
        let step = [
            1u32, 2, 5, 10, 20, 50, 100, 200, 500, 1000, 2000, 5000, 10000, 20000,
        ]
        .into_iter()
        .find(|k| k * l.cell >= 28)
        .unwrap_or(50000);
        let small = font(11.0, MUTED);
        for x in (0..u32::from(w)).step_by(step as usize) {
            let x = x as u16;
            let (px, _) = l.centre(x, 0);
            a.draw(&Text::new(
                x.to_string(),
                (px, y0 - 9),
                centre(small.clone()),
            ))
            .map_err(err)?;
        }
        for y in (0..u32::from(h)).step_by(step as usize) {
            let y = y as u16;
            let (_, py) = l.centre(0, y);
            a.draw(&Text::new(
                y.to_string(),
                (x0 - 6, py),
                small.clone().pos(Pos::new(HPos::Right, VPos::Center)),
            ))
            .map_err(err)?;
        }
        Ok(())
    }

    fn draw_paths<DB: DrawingBackend>(
        &self,
        a: &DrawingArea<DB, Shift>,
        l: &Layout,
    ) -> Result<(), DrawError> {
        let n = self.layers.len();
        let centres = |pts: &[[u16; 2]]| -> Vec<(i32, i32)> {
            pts.iter().map(|&[x, y]| l.centre(x, y)).collect()
        };
        let thin = (l.cell / 12).max(1);
        for layer in &self.layers {
            let colour = algorithm_colour(layer.algorithm);
            a.draw(&PathElement::new(
                centres(&layer.raw),
                colour.mix(0.55).stroke_width(thin),
            ))
            .map_err(err)?;
        }
        for (i, layer) in self.layers.iter().enumerate() {
            let colour = algorithm_colour(layer.algorithm);
            a.draw(&PathElement::new(
                centres(&layer.waypoints),
                colour.stroke_width(l.path_width(i, n)),
            ))
            .map_err(err)?;
        }
        let r = ((l.cell / 5).max(2)) as i32;
        for layer in &self.layers {
            let colour = algorithm_colour(layer.algorithm);
            for p in centres(&layer.waypoints) {
                a.draw(&Circle::new(p, r + 1, FREE.filled())).map_err(err)?;
                a.draw(&Circle::new(p, r, colour.filled())).map_err(err)?;
            }
        }
        // Start and goal on top.
        let r = ((l.cell * 2 / 5).max(6)) as i32;
        for (p, colour, label) in [(self.start, START, "S"), (self.goal, GOAL, "G")] {
            if p.x >= self.map.width || p.y >= self.map.height {
                continue;
            }
            let c = l.centre(p.x, p.y);
            a.draw(&Circle::new(c, r + 1, FREE.filled())).map_err(err)?;
            a.draw(&Circle::new(c, r, colour.filled())).map_err(err)?;
            if l.cell >= 14 {
                let size = f64::from(l.cell) * 0.5;
                a.draw(&Text::new(label, c, centre(font(size, FREE))))
                    .map_err(err)?;
            }
        }
        Ok(())
    }

    fn draw_legend<DB: DrawingBackend>(
        &self,
        a: &DrawingArea<DB, Shift>,
        l: &Layout,
    ) -> Result<(), DrawError> {
        let x = l.legend_x as i32;
        let mut y = (l.map_y + LEGEND_LINE / 2) as i32;
        let line = LEGEND_LINE as i32;
        let text_x = x + LEGEND_TEXT_DX as i32;
        let body = left(font(BODY_SIZE, INK));
        let small = left(font(SMALL_SIZE, MUTED));
        let swatch = |y: i32| [(x, y), (x + 34, y)];
        a.draw(&Text::new("Paths", (x, y), left(font(16.0, INK))))
            .map_err(err)?;
        y += line;
        let n = self.layers.len();
        for (i, layer) in self.layers.iter().enumerate() {
            let colour = algorithm_colour(layer.algorithm);
            let width = l.path_width(i, n).min(12);
            a.draw(&PathElement::new(
                swatch(y).to_vec(),
                colour.stroke_width(width),
            ))
            .map_err(err)?;
            a.draw(&Text::new(layer_line1(layer), (text_x, y), body.clone()))
                .map_err(err)?;
            y += line;
            a.draw(&Text::new(
                layer.line2.clone(),
                (text_x, y - 3),
                small.clone(),
            ))
            .map_err(err)?;
            y += line;
        }
        y += line / 2;
        let grey = MUTED;
        a.draw(&PathElement::new(
            swatch(y).to_vec(),
            grey.mix(0.55).stroke_width(2),
        ))
        .map_err(err)?;
        a.draw(&Text::new("raw ant path (thin)", (text_x, y), body.clone()))
            .map_err(err)?;
        y += line;
        a.draw(&PathElement::new(swatch(y).to_vec(), grey.stroke_width(5)))
            .map_err(err)?;
        a.draw(&Text::new(
            "output path (smoothed for OHACA)",
            (text_x, y),
            body.clone(),
        ))
        .map_err(err)?;
        y += line;
        a.draw(&Circle::new((x + 17, y), 5, FREE.filled()))
            .map_err(err)?;
        a.draw(&Circle::new((x + 17, y), 4, grey.filled()))
            .map_err(err)?;
        a.draw(&Text::new("waypoint", (text_x, y), body.clone()))
            .map_err(err)?;
        y += line;
        for (colour, label, p) in [(START, "start", self.start), (GOAL, "goal", self.goal)] {
            a.draw(&Circle::new((x + 17, y), 8, colour.filled()))
                .map_err(err)?;
            a.draw(&Text::new(
                self.endpoint_label(label, p),
                (text_x, y),
                body.clone(),
            ))
            .map_err(err)?;
            y += line;
        }
        a.draw(&Rectangle::new(
            [(x + 9, y - 8), (x + 25, y + 8)],
            BLOCKED.filled(),
        ))
        .map_err(err)?;
        a.draw(&Text::new("obstacle", (text_x, y), body.clone()))
            .map_err(err)?;
        y += line;
        if self.pheromone.is_some() {
            for k in 0..34 {
                let c = heat(f64::from(k) / 33.0);
                a.draw(&Rectangle::new(
                    [(x + k, y - 8), (x + k + 1, y + 8)],
                    c.filled(),
                ))
                .map_err(err)?;
            }
            a.draw(&Rectangle::new(
                [(x, y - 8), (x + 34, y + 8)],
                MUTED.stroke_width(1),
            ))
            .map_err(err)?;
            a.draw(&Text::new(
                "final pheromone (log scale)",
                (text_x, y),
                body.clone(),
            ))
            .map_err(err)?;
            y += line;
            a.draw(&Text::new(
                self.pheromone_label.clone(),
                (text_x, y - 3),
                small.clone(),
            ))
            .map_err(err)?;
        }
        Ok(())
    }
}

/// The point of row-major index `i` on a map `w` wide.
fn point_of(i: usize, w: u16) -> Point {
    let w = usize::from(w).max(1);
    Point::new(
        u16::try_from(i % w).unwrap_or(u16::MAX),
        u16::try_from(i / w).unwrap_or(u16::MAX),
    )
}

impl Picture for Scene {
    fn size(&self) -> (u32, u32) {
        let l = self.layout();
        (l.width, l.height)
    }

    fn draw<DB: DrawingBackend>(&self, a: &DrawingArea<DB, Shift>) -> Result<(), DrawError> {
        let l = self.layout();
        a.fill(&FREE).map_err(err)?;
        a.draw(&Text::new(
            self.title.clone(),
            (MARGIN as i32, 16),
            left(font(TITLE_SIZE, INK)),
        ))
        .map_err(err)?;
        a.draw(&Text::new(
            self.subtitle.clone(),
            (MARGIN as i32, 38),
            left(font(SUBTITLE_SIZE, MUTED)),
        ))
        .map_err(err)?;
        self.draw_map(a, &l)?;
        self.draw_paths(a, &l)?;
        self.draw_legend(a, &l)
    }
}

/// One line of a convergence chart.
#[derive(Clone, Debug, PartialEq)]
pub struct Series {
    /// The variant (gives the colour and the name).
    pub algorithm: Algorithm,
    /// Value after iteration 1, 2, ...; non-finite values are left out.
    pub values: Vec<f64>,
}

/// A convergence chart: one line per algorithm over the iterations.
#[derive(Clone, Debug, PartialEq)]
pub struct Convergence {
    /// Chart title.
    pub title: String,
    /// The y axis' description.
    pub y_label: String,
    /// The lines.
    pub series: Vec<Series>,
}

impl Picture for Convergence {
    fn size(&self) -> (u32, u32) {
        // Wider than 960 only when the title would not fit (a long file name).
        (960.max(text_width(&self.title, 20.0) + 2 * 18 + 8), 600)
    }

    fn draw<DB: DrawingBackend>(&self, a: &DrawingArea<DB, Shift>) -> Result<(), DrawError> {
        a.fill(&FREE).map_err(err)?;
        let finite = || {
            self.series
                .iter()
                .flat_map(|s| s.values.iter().copied())
                .filter(|v| v.is_finite())
        };
        let lo = finite().fold(f64::INFINITY, f64::min);
        let hi = finite().fold(f64::NEG_INFINITY, f64::max);
        let (lo, hi) = if lo.is_finite() && hi.is_finite() {
            let pad = ((hi - lo) * 0.08).max(0.5);
            (lo - pad, hi + pad)
        } else {
            (0.0, 1.0)
        };
        let n = self
            .series
            .iter()
            .map(|s| s.values.len())
            .max()
            .unwrap_or(1)
            .max(2);
        let mut chart = ChartBuilder::on(a)
            .caption(self.title.clone(), font(20.0, INK))
            .margin(18)
            .x_label_area_size(48)
            .y_label_area_size(64)
            .build_cartesian_2d(1.0f64..n as f64, lo..hi)
            .map_err(err)?;
        chart
            .configure_mesh()
            .x_desc("iteration")
            .y_desc(self.y_label.clone())
            .x_label_formatter(&|v| format!("{v:.0}"))
            .y_label_formatter(&|v| format!("{v:.1}"))
            .label_style(font(13.0, INK))
            .axis_desc_style(font(15.0, INK))
            .light_line_style(GRID.mix(0.6))
            .bold_line_style(GRID.mix(1.0))
            .draw()
            .map_err(err)?;
        // Earlier lines wider, so lines that coincide still show every colour.
        let n_series = self.series.len();
        for (i, s) in self.series.iter().enumerate() {
            let colour = algorithm_colour(s.algorithm);
            let width = 2 + u32::try_from(n_series - 1 - i).unwrap_or(0).min(4);
            let points: Vec<(f64, f64)> = s
                .values
                .iter()
                .enumerate()
                .filter(|(_, v)| v.is_finite())
                .map(|(i, v)| ((i + 1) as f64, *v))
                .collect();
            chart
                .draw_series(LineSeries::new(points, colour.stroke_width(width)))
                .map_err(err)?
                .label(display_name(s.algorithm))
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 24, y)], colour.stroke_width(width))
                });
        }
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperRight)
            .background_style(FREE.mix(0.9))
            .border_style(MUTED)
            .label_font(font(15.0, INK))
            .draw()
            .map_err(err)?;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::map::{Format as MapFormat, Map};

    fn scene(pheromone: bool) -> Scene {
        let map = Map::parse("......\n.##...\n......\n", "t", MapFormat::Text).unwrap();
        Scene {
            title: "t → g".into(),
            subtitle: "sub".into(),
            start: Point::new(0, 0),
            goal: Point::new(5, 2),
            layers: vec![Layer {
                algorithm: Algorithm::Ohaca,
                raw: vec![[0, 0], [1, 0], [2, 0], [3, 1], [4, 2], [5, 2]],
                waypoints: vec![[0, 0], [2, 0], [5, 2]],
                line1: "length 1".into(),
                line2: "raw 2".into(),
            }],
            pheromone: pheromone.then(|| (0..18).map(|i| 0.01 + i as f32).collect()),
            pheromone_label: "of OHACA".into(),
            metric: None,
            map,
        }
    }

    #[test]
    fn svg_and_png_agree_on_size() {
        let s = scene(true);
        let (w, h) = s.size();
        let svg = to_svg(&s).unwrap();
        assert!(svg.starts_with("<svg"), "{}", &svg[..60]);
        assert!(svg.contains(&format!("width=\"{w}\"")));
        assert!(svg.contains("OHACA: length 1"));
        let png = to_png(&s).unwrap();
        let img = image::load_from_memory(&png).unwrap().to_rgb8();
        assert_eq!((img.width(), img.height()), (w, h));
        // The middle of the first output segment has the path colour.
        let l = s.layout();
        let (a, b) = (l.centre(0, 0), l.centre(2, 0));
        let px = img.get_pixel(((a.0 + b.0) / 2) as u32, a.1 as u32).0;
        let c = algorithm_colour(Algorithm::Ohaca);
        assert_eq!(px, [c.0, c.1, c.2]);
        // An obstacle cell is obstacle-coloured.
        let (x, y) = l.centre(1, 1);
        let px = img.get_pixel(x as u32 + 3, y as u32 + 3).0;
        assert_eq!(px, [BLOCKED.0, BLOCKED.1, BLOCKED.2]);
        // Same input, same bytes.
        assert_eq!(to_png(&s).unwrap(), png);
        assert_eq!(to_svg(&s).unwrap(), svg);
    }

    #[test]
    fn text_is_rendered() {
        // Text needs the embedded font: the title area is not blank.
        let s = scene(false);
        let rgb = to_rgb(&s).unwrap();
        let (w, _) = s.size();
        let row_bytes = w as usize * 3;
        let title_rows = &rgb[row_bytes * 8..row_bytes * 26];
        assert!(title_rows.iter().any(|&b| b < 128), "title text drawn");
    }

    #[test]
    fn heat_ramp() {
        assert_eq!(heat(0.0), RGBColor(255, 255, 255));
        assert_eq!(heat(1.0), RGBColor(84, 39, 143));
        assert_eq!(heat(f64::NAN), RGBColor(255, 255, 255));
    }

    #[test]
    fn convergence_draws() {
        let c = Convergence {
            title: "c".into(),
            y_label: "y".into(),
            series: vec![
                Series {
                    algorithm: Algorithm::Aca,
                    values: vec![f64::INFINITY, 40.0, 38.0, 38.0],
                },
                Series {
                    algorithm: Algorithm::Ohaca,
                    values: vec![36.0; 3],
                },
            ],
        };
        // A title longer than the chart widens it.
        let long = Convergence {
            title: "a very long name of a map file, ".repeat(6),
            ..c.clone()
        };
        assert!(long.size().0 > 960 && long.size().1 == 600);
        let svg = to_svg(&c).unwrap();
        assert!(svg.contains("OHACA") && svg.contains("iteration"));
        let png = to_png(&c).unwrap();
        let img = image::load_from_memory(&png).unwrap();
        assert_eq!((img.width(), img.height()), (960, 600));
        // Empty and all-infinite series do not fail.
        let e = Convergence {
            title: "e".into(),
            y_label: "y".into(),
            series: vec![Series {
                algorithm: Algorithm::Aca,
                values: vec![f64::INFINITY],
            }],
        };
        to_png(&e).unwrap();
    }

    #[test]
    fn base64_is_rfc_4648() {
        for (plain, coded) in [
            ("", ""),
            ("f", "Zg=="),
            ("fo", "Zm8="),
            ("foo", "Zm9v"),
            ("foob", "Zm9vYg=="),
            ("fooba", "Zm9vYmE="),
            ("foobar", "Zm9vYmFy"),
        ] {
            assert_eq!(base64(plain.as_bytes()), coded);
        }
        assert_eq!(base64(&[0xFB, 0xFF]), "+/8=");
    }

    #[test]
    fn embedding_the_font_keeps_one_document() {
        let svg =
            "<svg width=\"1\" height=\"1\">\n<text font-family=\"sans-serif\">a</text>\n</svg>\n";
        let e = embed_font(svg);
        assert!(e.starts_with("<svg width=\"1\" height=\"1\">\n<defs><style>@font-face{"));
        assert!(e.contains("<text font-family=\"OhacaGo, sans-serif\">a</text>"));
        assert!(e.ends_with("</svg>\n"));
    }

    #[test]
    fn formats() {
        assert_eq!(Format::of(Path::new("a.SVG")), Some(Format::Svg));
        assert_eq!(Format::of(Path::new("a.png")), Some(Format::Png));
        assert_eq!(Format::of(Path::new("a.jpg")), None);
        assert_eq!(Format::of(Path::new("a")), None);
    }
}
