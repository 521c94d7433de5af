//! How many trace threads each layer's lattice points get (GpuLayer::lanes). One thread per
//! point traces the point's samples one after another, starting the next as soon as one
//! ends; a GPU then sees too few threads for a sparse layer of many samples (a fovea): on an
//! H100 the thesis' layers traced 3–4× fewer samples per second than regular 1 spp
//! (reports/gpu-h100-1440x1600). Lanes spread a point's samples over threads; each lane
//! should keep several, or it idles while its workgroup's longest path runs, and a layer of
//! 1 spp gets nothing from them (reports/gpu-h100-split-1440x1600).

use crate::foveation::FoveationConfig;
use crate::shader_layout::MAX_TRACE_LANES;

/// The rule: layer lanes = the largest power of two ≤ spp / `samples_per_lane`, at least 1,
/// at most `max_lanes`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TraceLanes {
    pub max_lanes: u32,
    pub samples_per_lane: u32,
}

impl TraceLanes {
    /// One thread per point: what a CPU driver runs best, where threads add work, not
    /// parallelism.
    pub const ONE: Self = Self {
        max_lanes: 1,
        samples_per_lane: 1,
    };

    /// Checked: `max_lanes` a power of two up to MAX_TRACE_LANES, `samples_per_lane` ≥ 1.
    pub fn new(max_lanes: u32, samples_per_lane: u32) -> Result<Self, String> {
        if !max_lanes.is_power_of_two() || max_lanes > MAX_TRACE_LANES {
            return Err(format!(
                "trace split {max_lanes}: give a power of two from 1 to {MAX_TRACE_LANES} \
                 (the most threads per lattice point)"
            ));
        }
        if samples_per_lane == 0 {
            return Err("samples per lane 0: give at least 1".into());
        }
        Ok(Self {
            max_lanes,
            samples_per_lane,
        })
    }

    /// Threads for each point of a layer of `spp` samples.
    pub fn of_layer(&self, spp: u32) -> u32 {
        let wanted = (spp / self.samples_per_lane).max(1);
        (1u32 << wanted.ilog2()).min(self.max_lanes)
    }

    /// The most lanes of `config`'s layers: the plan reserves work-list slots in multiples
    /// of it, and every point may need that many slots.
    pub fn unit(&self, config: &FoveationConfig) -> u32 {
        config
            .layers
            .iter()
            .map(|l| self.of_layer(l.spp))
            .max()
            .unwrap_or(1)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lanes_are_powers_of_two_within_the_cap_and_the_samples() {
        let lanes = TraceLanes::new(8, 2).unwrap();
        let got: Vec<u32> = [1, 2, 3, 4, 7, 8, 16, 17, 64, 1000]
            .iter()
            .map(|&spp| lanes.of_layer(spp))
            .collect();
        assert_eq!(got, [1, 1, 1, 2, 2, 4, 8, 8, 8, 8]);
        assert_eq!(TraceLanes::ONE.of_layer(1000), 1);
        let mut config = FoveationConfig::thesis();
        config.layers[0].spp = 64;
        assert_eq!(lanes.unit(&config), 8);
        assert_eq!(TraceLanes::new(4, 1).unwrap().unit(&config), 4);
        assert!(TraceLanes::new(3, 1).is_err());
        assert!(TraceLanes::new(128, 1).is_err());
        assert!(TraceLanes::new(4, 0).is_err());
    }
}
