//! The images of an image-valued quantity: the reference's and each rule's
//! at its largest budget, with error heat maps.

use super::Page;
use super::rows::Row;
use super::section::{cell, label, off_cell};

/// An image the report shows, with its files (PNG, PFM, and the error heat
/// map's PNG where it is a rule's).
#[derive(Debug, Clone)]
pub struct Picture {
    /// What it is, with its errors.
    pub caption: String,
    /// Its width in pixels.
    pub width: usize,
    /// The PNG's file name (W-Grey's 8-bit mapping).
    pub png: String,
    /// The PFM's file name (32-bit floats).
    pub pfm: String,
    /// The error heat map's PNG file name, for a rule's image.
    pub error_png: Option<String>,
    /// The files' names and bytes.
    pub files: Vec<(String, Vec<u8>)>,
}

/// The reference's image and each rule's mean image at its largest budget,
/// with heat maps of `|image - reference|` (the largest channel per pixel),
/// each on its own scale (on a common one the better rules' maps were
/// black beside the centre ray's), stated in its caption.
pub(super) fn pictures(
    page: &Page,
    q: &str,
    [width, height]: [usize; 2],
    reference: &[f64],
    rows: &[Row],
) -> Result<Vec<Picture>, String> {
    use crate::whitted::image::Image;
    let image = |v: &[f64]| -> Result<Image, String> {
        let pixels = v
            .chunks_exact(3)
            .map(|c| crate::value::Rgb::new(c[0], c[1], c[2]))
            .collect();
        Image::new(width, height, pixels).map_err(|e| e.to_string())
    };
    if reference.len() != 3 * width * height {
        return Ok(Vec::new());
    }
    let reference_image = image(reference)?;
    let base = format!("{}-{q}", page.name);
    let png = |i: &Image| i.png().map_err(|e| e.to_string());
    let pfm = |i: &Image| i.pfm().map_err(|e| e.to_string());
    let mut out = vec![Picture {
        caption: "the reference".into(),
        width,
        png: format!("{base}-reference.png"),
        pfm: format!("{base}-reference.pfm"),
        error_png: None,
        files: vec![
            (format!("{base}-reference.png"), png(&reference_image)?),
            (format!("{base}-reference.pfm"), pfm(&reference_image)?),
        ],
    }];
    // Each rule's row at its largest budget whose value is a whole image.
    let last: Vec<&Row> = (0..page.rules.len())
        .filter_map(|i| {
            rows.iter()
                .filter(|r| r.rule_index == i && r.value.len() == reference.len())
                .max_by_key(|r| r.budget)
        })
        .collect();
    let images = last
        .iter()
        .map(|r| image(&r.value))
        .collect::<Result<Vec<_>, _>>()?;
    for (r, img) in last.iter().zip(&images) {
        let worst = img
            .pixels()
            .iter()
            .zip(reference_image.pixels())
            .map(|(a, b)| (a - b).abs().max())
            .filter(|e| e.is_finite())
            .fold(0.0f64, f64::max);
        let scale = if worst > 0.0 { worst } else { 1.0 };
        let name = label(page, r.rule_index)
            .chars()
            .map(|c| if c.is_ascii_alphanumeric() { c } else { '-' })
            .collect::<String>();
        let stem = format!("{base}-{}-{name}-n{}", r.rule_index, r.budget);
        let errors = img
            .error_map(&reference_image, scale)
            .map_err(|e| e.to_string())?;
        let off = r
            .display_off
            .map(|o| format!(", {} 8-bit values off", off_cell(Some(o))))
            .unwrap_or_default();
        out.push(Picture {
            caption: format!(
                "{}, n = {}: the mean over repeats, its map white at {worst:.2e} absolute; the \
                 row's errors over repeats {} RMS, {} largest channel (relative){off}",
                label(page, r.rule_index),
                r.budget,
                cell(r.rel_error),
                cell(r.max_error),
            ),
            width,
            png: format!("{stem}.png"),
            pfm: format!("{stem}.pfm"),
            error_png: Some(format!("{stem}-error.png")),
            files: vec![
                (format!("{stem}.png"), png(img)?),
                (format!("{stem}.pfm"), pfm(img)?),
                (format!("{stem}-error.png"), png(&errors)?),
            ],
        });
    }
    if let Some(first) = out.first_mut() {
        first.caption = "the reference; beside each rule's image its error map: the largest \
                         channel error per pixel, from black (0) through red and yellow to white \
                         (that image's largest)"
            .into();
    }
    Ok(out)
}
