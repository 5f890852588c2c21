//! Images of a render: 8-bit PNG by W-Grey's mapping, and PFM floats.
//!
//! W-Grey maps an intensity to an integer `0..=255` for display, per R, G,
//! B. Here `q = round(255 clamp(I, 0, 1))`: intensities above 1 saturate at
//! 255, and two intensities closer than `1/510` (half a step) can map to
//! the same integer, so a pixel error below `1/510` no longer shows in the
//! PNG (the 8-bit quantisation floor).
//!
//! PFM (Portable Float Map) keeps the intensities as 32-bit floats: a text
//! header `PF\n<width> <height>\n-1.0\n` (the negative scale says little
//! endian), then the rows of RGB triples from the bottom row up.
//!
//! ```
//! use lightquad::value::Rgb;
//! use lightquad::whitted::image::{Image, grey};
//!
//! assert_eq!((grey(-0.5), grey(0.5), grey(2.0)), (0, 128, 255));
//! // Half a step: 1/510 rounds up, just below it down.
//! assert_eq!((grey(1.0 / 510.0), grey(0.99 / 510.0)), (1, 0));
//! let image = Image::new(2, 1, vec![Rgb::new(1.0, 0.0, 0.0), Rgb::new(0.0, 0.0, 1.0)])?;
//! let pfm = image.pfm()?;
//! assert!(pfm.starts_with(b"PF\n2 1\n-1.0\n"));
//! assert_eq!(pfm.len(), 12 + 2 * 3 * 4);
//! // A value 32-bit floats cannot hold is refused, not written as infinity.
//! let bright = Image::new(1, 1, vec![Rgb::new(1e39, 0.0, 0.0)])?;
//! assert!(bright.pfm().is_err());
//! # Ok::<(), lightquad::QuadError>(())
//! ```

use std::path::Path;

use crate::error::QuadError;
use crate::value::Rgb;

/// W-Grey: `round(255 clamp(v, 0, 1))` (NaN maps to 0).
pub fn grey(v: f64) -> u8 {
    if v.is_nan() {
        return 0;
    }
    (255.0 * v.clamp(0.0, 1.0)).round() as u8
}

/// An RGB image, pixels in rows from the top, `j * width + i`.
#[derive(Debug, Clone, PartialEq)]
pub struct Image {
    width: usize,
    height: usize,
    pixels: Vec<Rgb>,
}

impl Image {
    /// The image of `pixels` (exactly `width height` of them).
    pub fn new(width: usize, height: usize, pixels: Vec<Rgb>) -> Result<Self, QuadError> {
        if width == 0 || height == 0 || pixels.len() != width * height {
            return Err(QuadError::invalid(
                "pixels",
                pixels.len(),
                format!("width x height = {width} x {height} > 0 pixels"),
            ));
        }
        Ok(Image {
            width,
            height,
            pixels,
        })
    }

    /// Width.
    pub fn width(&self) -> usize {
        self.width
    }

    /// Height.
    pub fn height(&self) -> usize {
        self.height
    }

    /// The pixels in rows from the top.
    pub fn pixels(&self) -> &[Rgb] {
        &self.pixels
    }

    /// The 8-bit RGB bytes of W-Grey, rows from the top.
    pub fn bytes(&self) -> Vec<u8> {
        self.pixels
            .iter()
            .flat_map(|p| [grey(p.x), grey(p.y), grey(p.z)])
            .collect()
    }

    /// The PNG file's bytes (8-bit RGB, W-Grey).
    pub fn png(&self) -> Result<Vec<u8>, QuadError> {
        let mut out = Vec::new();
        let fail = |e: png::EncodingError| QuadError::invalid("png", e, "an encodable image");
        let mut encoder = png::Encoder::new(&mut out, self.width as u32, self.height as u32);
        encoder.set_color(png::ColorType::Rgb);
        encoder.set_depth(png::BitDepth::Eight);
        let mut writer = encoder.write_header().map_err(fail)?;
        writer.write_image_data(&self.bytes()).map_err(fail)?;
        writer.finish().map_err(fail)?;
        Ok(out)
    }

    /// The PFM file's bytes (little-endian f32 RGB, rows from the bottom).
    ///
    /// A value that 32-bit floats cannot hold (beyond 3.4e38, or not a
    /// number) is an error naming its pixel, never an infinity in the file.
    pub fn pfm(&self) -> Result<Vec<u8>, QuadError> {
        let mut out = format!("PF\n{} {}\n-1.0\n", self.width, self.height).into_bytes();
        for (j, row) in self.pixels.chunks(self.width).enumerate().rev() {
            for (i, p) in row.iter().enumerate() {
                for c in [p.x, p.y, p.z] {
                    let f = c as f32;
                    if !f.is_finite() {
                        return Err(QuadError::invalid(
                            format!("pixel [{i}, {j}]"),
                            format!("{:?}", p.as_slice()),
                            "values a 32-bit float holds (finite, at most 3.4e38 in size)",
                        ));
                    }
                    out.extend_from_slice(&f.to_le_bytes());
                }
            }
        }
        Ok(out)
    }

    /// The heat map of `|self - reference|` (the largest channel per
    /// pixel), scaled so that `scale` is white: black, red, yellow, white.
    pub fn error_map(&self, reference: &Image, scale: f64) -> Result<Image, QuadError> {
        if reference.width != self.width || reference.height != self.height {
            return Err(QuadError::invalid(
                "reference",
                format!("{} x {}", reference.width, reference.height),
                format!("an image of {} x {}", self.width, self.height),
            ));
        }
        let pixels = self
            .pixels
            .iter()
            .zip(&reference.pixels)
            .map(|(a, b)| {
                let e = ((a - b).abs().max() / scale).clamp(0.0, 1.0) * 3.0;
                Rgb::new(
                    e.min(1.0),
                    (e - 1.0).clamp(0.0, 1.0),
                    (e - 2.0).clamp(0.0, 1.0),
                )
            })
            .collect();
        Image::new(self.width, self.height, pixels)
    }

    /// Writes the PNG to `path`.
    pub fn write_png(&self, path: &Path) -> Result<(), QuadError> {
        std::fs::write(path, self.png()?).map_err(|e| {
            QuadError::invalid("path", path.display(), format!("a writable file ({e})"))
        })
    }

    /// Writes the PFM to `path`.
    pub fn write_pfm(&self, path: &Path) -> Result<(), QuadError> {
        std::fs::write(path, self.pfm()?).map_err(|e| {
            QuadError::invalid("path", path.display(), format!("a writable file ({e})"))
        })
    }
}
