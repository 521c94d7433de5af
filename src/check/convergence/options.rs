//! What a convergence measurement renders: size, sample counts, seeds and references.

use crate::render::RenderSettings;
use serde::Serialize;

/// Samples per pixel of one reference render (as `bench::quality`'s): no single dispatch runs
/// long enough to trip a GPU watchdog, and the chunks' spread measures the reference's noise.
pub const REFERENCE_CHUNK_SPP: u32 = 32;

/// What to measure.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ConvergenceOptions {
    pub width: u32,
    pub height: u32,
    /// Samples per pixel of the measured points, e.g. 1, 2, 4, …, 64; at least two distinct.
    pub spp: Vec<u32>,
    /// Independent renders (distinct seeds) per point; their MSEs are averaged.
    pub seeds: u32,
    /// Samples per pixel of each integrator's reference, rendered in chunks of
    /// [`REFERENCE_CHUNK_SPP`] (rounded up to whole chunks, at least two). At least 8 × the
    /// largest point's spp, so that the reference's noise is a small correction.
    pub reference_spp: u32,
    pub max_bounces: u32,
    /// First seed of the measured renders; another value gives an independent measurement.
    pub seed: u32,
}

impl Default for ConvergenceOptions {
    fn default() -> Self {
        Self {
            width: 64,
            height: 64,
            spp: (0..7).map(|k| 1 << k).collect(),
            seeds: 4,
            reference_spp: 2048,
            max_bounces: 8,
            seed: 1,
        }
    }
}

impl ConvergenceOptions {
    /// Rejects option sets that cannot give a fit or a trustworthy reference.
    pub fn validate(&self) -> Result<(), String> {
        let mut distinct = self.spp.clone();
        distinct.sort_unstable();
        distinct.dedup();
        if distinct.len() < 2 || distinct[0] == 0 {
            return Err(format!(
                "convergence needs at least two distinct positive spp values to fit a slope, got {:?}",
                self.spp
            ));
        }
        if self.seeds == 0 {
            return Err("convergence needs at least one seed per point".into());
        }
        let largest = *distinct.last().expect("two values");
        if (self.reference_spp as u64) < 8 * largest as u64 {
            return Err(format!(
                "reference spp {} is less than 8 x the largest point's {largest} spp: the \
                 reference would be as noisy as the images it judges",
                self.reference_spp
            ));
        }
        RenderSettings {
            width: self.width,
            height: self.height,
            spp: largest.max(REFERENCE_CHUNK_SPP),
            max_bounces: self.max_bounces,
            ..RenderSettings::default()
        }
        .validate()
    }

    /// Chunks of the reference and samples per chunk.
    pub(super) fn reference_chunks(&self) -> (u32, u32) {
        let chunks = self.reference_spp.div_ceil(REFERENCE_CHUNK_SPP).max(2);
        (chunks, self.reference_spp.div_ceil(chunks))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn options_need_a_slope_and_a_quiet_reference() {
        assert!(ConvergenceOptions::default().validate().is_ok());
        let one = ConvergenceOptions {
            spp: vec![4, 4],
            ..Default::default()
        };
        assert!(one.validate().unwrap_err().contains("two distinct"));
        let noisy = ConvergenceOptions {
            reference_spp: 256,
            ..Default::default()
        };
        assert!(noisy.validate().unwrap_err().contains("8 x"));
        assert_eq!(ConvergenceOptions::default().reference_chunks(), (64, 32));
        let small = ConvergenceOptions {
            spp: vec![1, 2],
            reference_spp: 16,
            ..Default::default()
        };
        assert_eq!(small.reference_chunks(), (2, 8));
    }
}
