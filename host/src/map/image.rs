//! Plain black-and-white images as maps (a PNG or PGM given directly, no YAML), and the image
//! reading that ROS maps share: a pixel is blocked when it is darker than 50 % (mean of R, G, B
//! below 127.5; a transparent pixel counts as white). Such a map has no resolution: positions
//! are cells.

use std::path::Path;

use image::RgbaImage;

use super::bitmap::{Map, MAX_SIDE};
use super::error::MapError;

/// Mean of R, G and B.
pub(super) fn grey(px: &image::Rgba<u8>) -> f64 {
    let [r, g, b, _] = px.0;
    (f64::from(r) + f64::from(g) + f64::from(b)) / 3.0
}

/// Read an image file as RGBA (grey images are replicated into R, G, B).
pub fn read_image(path: &Path) -> Result<RgbaImage, MapError> {
    let name = path.display().to_string();
    let err = |problem: String| MapError::File {
        path: name.clone(),
        problem,
    };
    let bytes = std::fs::read(path).map_err(|e| err(format!("cannot read the image: {e}")))?;
    decode_image(&bytes, &name)
}

/// Decode the bytes of a PNG or PGM image as RGBA, as [`read_image`] does for a file; `name`
/// stands for the file in errors.
pub fn decode_image(bytes: &[u8], name: &str) -> Result<RgbaImage, MapError> {
    let err = |problem: String| MapError::File {
        path: name.to_string(),
        problem,
    };
    let format = image::guess_format(bytes)
        .map_err(|_| err("not a PNG or PGM image (unknown file signature)".to_string()))?;
    let img = image::load_from_memory_with_format(bytes, format)
        .map_err(|e| err(format!("cannot decode the image: {e}")))?;
    let (w, h) = (img.width(), img.height());
    if w == 0 || h == 0 {
        return Err(err("the image is empty".to_string()));
    }
    let too_big = |side: &str, v: u32| err(format!("image {side} {v} is more than {MAX_SIDE}"));
    if usize::try_from(w).map_or(true, |w| w > MAX_SIDE) {
        return Err(too_big("width", w));
    }
    if usize::try_from(h).map_or(true, |h| h > MAX_SIDE) {
        return Err(too_big("height", h));
    }
    Ok(img.to_rgba8())
}

/// Image sides as `u16` (checked by [`decode_image`]; larger sides clamp to `u16::MAX`).
pub(super) fn sides(img: &RgbaImage) -> (u16, u16) {
    (
        u16::try_from(img.width()).unwrap_or(u16::MAX),
        u16::try_from(img.height()).unwrap_or(u16::MAX),
    )
}

/// Load a plain image as a map: darker than 50 % is blocked (transparent counts as white).
pub fn load_image(path: &Path) -> Result<Map, MapError> {
    read_image(path).map(|img| image_map(&img))
}

/// A decoded plain image as a map: darker than 50 % is blocked (transparent counts as white).
pub fn image_map(img: &RgbaImage) -> Map {
    let (w, h) = sides(img);
    Map::from_fn(w, h, |x, y| {
        let px = img.get_pixel(u32::from(x), u32::from(y));
        // Composite over white: value * a + 255 * (1 - a).
        let a = f64::from(px.0[3]) / 255.0;
        let v = grey(px) * a + 255.0 * (1.0 - a);
        v < 127.5
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn from_memory_matches_the_files() {
        let pgm = concat!(env!("CARGO_MANIFEST_DIR"), "/assets/ros/lab.pgm");
        let img = decode_image(&std::fs::read(pgm).unwrap(), "lab.pgm").unwrap();
        assert_eq!(image_map(&img), load_image(Path::new(pgm)).unwrap());
        let e = decode_image(b"P5\n2 2\n255\n", "short.pgm").unwrap_err();
        assert!(e.to_string().starts_with("short.pgm: cannot decode"), "{e}");
        let e = decode_image(b"no image", "x.png").unwrap_err();
        assert!(e.to_string().contains("unknown file signature"), "{e}");
    }
}
