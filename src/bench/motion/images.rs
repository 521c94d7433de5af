//! The motion run's animation: per frame, the left eye's reference, every sequence and the
//! error of the temporal-history sequence side by side, scaled down so the animated PNG
//! stays a file one opens in a browser, with each sequence's gaze marked.

use super::script::Sequence;
use crate::bench::error::BenchError;
use crate::bench::files::ANIMATION_FRAME_MS;
use crate::bench::plots::{animated_strip, Panel};
use crate::metrics::magma_rgb8;
use crate::render::output::linear_to_srgb8;
use std::collections::BTreeMap;
use std::path::Path;

/// Panels are at most this wide: box-filtered down by a whole factor.
const PANEL_MAX_WIDTH: u32 = 240;

/// The frames of one scene's animation as they are rendered, in any order.
pub struct Animation {
    width: u32,
    height: u32,
    factor: u32,
    labels: Vec<String>,
    /// (frame, panel) → the panel's pixels.
    panels: BTreeMap<(u32, usize), Vec<u8>>,
}

impl Animation {
    /// An animation of `width` × `height` eye images; `sequences` in the run's order.
    pub fn new(width: u32, height: u32, reference_spp: u32, sequences: &[Sequence]) -> Self {
        let factor = width.div_ceil(PANEL_MAX_WIDTH).max(1);
        // Short captions: a panel may be under 100 px wide.
        let mut labels = vec![format!("ref {reference_spp} spp")];
        labels.extend(sequences.iter().map(|s| {
            let history = if s.temporal { "on" } else { "off" };
            format!("{history} {} spp", s.spp)
        }));
        labels.push("error, on".into());
        Self {
            width,
            height,
            factor,
            labels,
            panels: BTreeMap::new(),
        }
    }

    fn size(&self) -> (u32, u32) {
        (self.width / self.factor, self.height / self.factor)
    }

    /// The reference of frame `frame` (the left eye's linear RGB).
    pub fn add_reference(&mut self, frame: u32, rgb: &[f32]) {
        let small = self.shrink(rgb);
        self.panels.insert((frame, 0), linear_to_srgb8(&small));
    }

    /// Sequence `index`'s frame, its gaze (pixels of the full image) marked; the history-on
    /// sequence also gives the error panel against `reference`, over the `visible` pixels
    /// (the lens hides the others: no error is shown there).
    #[allow(clippy::too_many_arguments)]
    pub fn add_sequence(
        &mut self,
        frame: u32,
        index: usize,
        sequence: &Sequence,
        rgb: &[f32],
        reference: &[f32],
        visible: &[bool],
        gaze: [f64; 2],
    ) -> Result<(), BenchError> {
        let small = self.shrink(rgb);
        let mut rgb8 = linear_to_srgb8(&small);
        self.mark(&mut rgb8, gaze);
        self.panels.insert((frame, 1 + index), rgb8);
        if sequence.temporal {
            // Per pixel: sqrt of the relMSE summand, so 1 means an error the size of the
            // reference itself.
            let error: Vec<f32> = rgb
                .chunks_exact(3)
                .zip(reference.chunks_exact(3))
                .zip(visible)
                .map(|((t, r), &seen)| {
                    if !seen {
                        return 0.0;
                    }
                    let sum: f32 = (0..3)
                        .map(|c| (t[c] - r[c]).powi(2) / (r[c] * r[c] + 0.01))
                        .sum();
                    (sum / 3.0).sqrt()
                })
                .collect();
            let small = self.shrink_scalar(&error);
            let (w, h) = self.size();
            self.panels
                .insert((frame, self.labels.len() - 1), magma_rgb8(&small, w, h)?);
        }
        Ok(())
    }

    /// Writes the animation if every panel of every one of `frames` frames is there (a
    /// resumed run that skipped a sequence renders it again for its pictures first).
    pub fn write(&self, path: &Path, frames: u32) -> Result<bool, BenchError> {
        let (w, h) = self.size();
        let mut all = Vec::with_capacity(frames as usize);
        for k in 0..frames {
            let mut row = Vec::with_capacity(self.labels.len());
            for (i, label) in self.labels.iter().enumerate() {
                let Some(rgb8) = self.panels.get(&(k, i)) else {
                    return Ok(false);
                };
                row.push(Panel {
                    label: label.clone(),
                    width: w,
                    height: h,
                    rgb8: rgb8.clone(),
                });
            }
            all.push(row);
        }
        animated_strip(path, &all, ANIMATION_FRAME_MS)?;
        Ok(true)
    }

    /// Box filter by the whole factor, in linear light.
    fn shrink(&self, rgb: &[f32]) -> Vec<f32> {
        let (w, h) = self.size();
        let f = self.factor as usize;
        let mut out = Vec::with_capacity((w * h * 3) as usize);
        for y in 0..h as usize {
            for x in 0..w as usize {
                for c in 0..3 {
                    let mut sum = 0.0;
                    for dy in 0..f {
                        for dx in 0..f {
                            let i = (y * f + dy) * self.width as usize + x * f + dx;
                            sum += rgb[3 * i + c];
                        }
                    }
                    out.push(sum / (f * f) as f32);
                }
            }
        }
        out
    }

    fn shrink_scalar(&self, values: &[f32]) -> Vec<f32> {
        let rgb: Vec<f32> = values.iter().flat_map(|&v| [v, v, v]).collect();
        self.shrink(&rgb).chunks_exact(3).map(|p| p[0]).collect()
    }

    /// A small cross at the gaze: white arms with black ends, visible on any background.
    fn mark(&self, rgb8: &mut [u8], gaze: [f64; 2]) {
        let (w, h) = self.size();
        let (gx, gy) = (
            (gaze[0] / self.factor as f64) as i64,
            (gaze[1] / self.factor as f64) as i64,
        );
        for d in -4i64..=4 {
            let colour = if d.abs() >= 3 { 0 } else { 255 };
            for (x, y) in [(gx + d, gy), (gx, gy + d)] {
                if (0..w as i64).contains(&x) && (0..h as i64).contains(&y) {
                    let i = 3 * (y as usize * w as usize + x as usize);
                    rgb8[i..i + 3].fill(colour);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_animation_is_written_only_when_complete_and_reads_back_as_apng() {
        let sequences = Sequence::all(2);
        let (w, h) = (500, 40);
        let mut a = Animation::new(w, h, 64, &sequences);
        // 500 px wide panels are shrunk 3× to 166 px.
        assert_eq!(a.size(), (166, 13));
        let grey = vec![0.5f32; (w * h * 3) as usize];
        let all = vec![true; (w * h) as usize];
        let dir = crate::test_dir::TestDir::new("anim");
        let path = dir.join("a.png");
        for k in 0..3 {
            a.add_reference(k, &grey);
            for (i, s) in sequences.iter().enumerate() {
                a.add_sequence(k, i, s, &grey, &grey, &all, [250.0, 20.0])
                    .unwrap();
            }
            if k < 2 {
                assert!(!a.write(&path, 3).unwrap(), "frame {k} is not the last");
            }
        }
        assert!(a.write(&path, 3).unwrap());
        let decoder = png::Decoder::new(std::fs::File::open(&path).unwrap());
        let reader = decoder.read_info().unwrap();
        let info = reader.info();
        let control = info.animation_control().expect("an animated PNG");
        assert_eq!(control.num_frames, 3);
        // Five panels: reference, three sequences, error.
        assert_eq!(info.width, 5 * 166 + 4 * crate::bench::plots::STRIP_GAP);
    }
}
