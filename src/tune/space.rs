//! What `fovea tune` searches: foveation configs built from a few layers (count, radii,
//! lattice spacings, spp, denoising and the lattice filter per layer), drawn at random from a seed and then mutated
//! around the best ones found. Everything here is pure: the same seed and the same measured
//! scores give the same candidates.

use crate::check::rng::Rng;
use crate::foveation::{FoveationConfig, Layer, DEFAULT_DENOISE_SIGMA, THESIS_OCCLUSION_DEG};

/// The grid the search draws from (and moves on when it mutates).
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Space {
    /// Most finite layers before the background one.
    pub max_inner_layers: usize,
    /// Layer radii, degrees from the gaze, ascending.
    pub radii_deg: Vec<f32>,
    /// Lattice spacings, ascending.
    pub spacings: Vec<u32>,
    /// Samples per target pixel, ascending.
    pub spp: Vec<u32>,
    /// The spp of the baselines (regular rendering and the thesis' layers).
    pub baseline_spp: Vec<u32>,
    /// Denoiser iterations a sparse layer may take (0 = none), ascending.
    pub denoise: Vec<u32>,
    /// Acuity limits a denoised layer may take, in minimum angles of resolution (0 = none),
    /// ascending. A limited denoiser keeps the gaze sharp, so the fovea may take one too.
    /// Plans from before the limit have none.
    #[serde(default = "no_filter")]
    pub denoise_mar: Vec<f32>,
    /// Luminance edge-stops a denoised layer may take, in standard deviations of the local
    /// noise, ascending. Tight keeps a fovea's shading detail: a 20° 4-spp fovea stopped at
    /// 0.5 reached regular 4 spp on cornell, bunny-high (every render seed judged) and the
    /// textured room in motion, stopped at 4 not on bunny-high. Plans from before the setting
    /// have only the default.
    #[serde(default = "default_sigma")]
    pub denoise_sigma: Vec<f32>,
    /// Lattice filter widths a sparse layer may take, in minimum angles of resolution at the
    /// eccentricity (0 = none), ascending. Plans from before the filter have none.
    #[serde(default = "no_filter")]
    pub filter_mar: Vec<f32>,
    /// Uniform lattice filter widths (pixels) the regular baselines are measured with too,
    /// beside none: the uniform renderer's own reconstruction at each strength.
    #[serde(default)]
    pub baseline_filter_px: Vec<f32>,
    /// Radii of the full-resolution foveae measured as baselines: at each radius and each
    /// baseline spp above 1, a fovea at that spp inside a regular 1-spp frame. They foveate
    /// samples, not pixels, which random draws seldom reach (every layer at spacing 1, the
    /// fovea wide); on cornell in motion 30° at 4 spp came within 0.002 JOD of regular 4
    /// spp. Plans from before them have none.
    #[serde(default)]
    pub spp_fovea_radii_deg: Vec<f32>,
    /// Fractions of its points a layer may trace per frame (1 = all), ascending: samples
    /// foveated below 1 spp at any spacing. Plans from before them have only 1.
    #[serde(default = "every_point")]
    pub fractions: Vec<u32>,
    /// Blend band width of every candidate, degrees.
    pub blend_deg: f32,
    /// Occlusion mask of every candidate (the headset's lens), degrees from the view axis.
    pub occlusion_deg: Option<f32>,
}

/// serde's `default = "..."` needs a function path.
fn no_filter() -> Vec<f32> {
    vec![0.0]
}

/// serde's `default = "..."` needs a function path.
fn default_sigma() -> Vec<f32> {
    vec![DEFAULT_DENOISE_SIGMA]
}

/// serde's `default = "..."` needs a function path.
fn every_point() -> Vec<u32> {
    vec![1]
}

impl Space {
    /// The search `fovea tune` runs by default: up to three layers and a background, radii
    /// from 3° to 40°, spacings 1–6, 1–16 spp, up to 3 denoiser iterations (limited to 2 or 4
    /// minimum angles of resolution, or not; stopping at 0.5, 1 or 4 σ of luminance), lattice
    /// filters 0.5–2 minimum angles of resolution wide; baselines at 1, 2 and 4 spp, regular
    /// ones also with uniform lattice filters 1 and 2 pixels wide.
    pub fn standard() -> Self {
        Self {
            max_inner_layers: 3,
            radii_deg: vec![
                3.0, 4.0, 5.0, 6.0, 8.0, 10.0, 12.0, 15.0, 20.0, 25.0, 30.0, 40.0,
            ],
            spacings: vec![1, 2, 3, 4, 5, 6],
            spp: vec![1, 2, 4, 8, 16],
            baseline_spp: vec![1, 2, 4],
            denoise: vec![0, 1, 2, 3],
            denoise_mar: vec![0.0, 2.0, 4.0],
            denoise_sigma: vec![0.5, 1.0, DEFAULT_DENOISE_SIGMA],
            filter_mar: vec![0.0, 0.5, 1.0, 2.0],
            baseline_filter_px: vec![1.0, 2.0],
            spp_fovea_radii_deg: vec![20.0, 30.0],
            fractions: vec![1, 2, 4],
            blend_deg: 1.0,
            occlusion_deg: Some(THESIS_OCCLUSION_DEG),
        }
    }

    /// A small search (`--space small`): one layer and a background, few values of each.
    pub fn small() -> Self {
        Self {
            max_inner_layers: 1,
            radii_deg: vec![6.0, 15.0],
            spacings: vec![1, 2, 4],
            spp: vec![1, 2],
            baseline_spp: vec![1, 2],
            denoise: vec![0],
            denoise_mar: no_filter(),
            denoise_sigma: default_sigma(),
            filter_mar: no_filter(),
            baseline_filter_px: Vec::new(),
            spp_fovea_radii_deg: Vec::new(),
            fractions: every_point(),
            ..Self::standard()
        }
    }

    /// The configs every search measures first, whatever the seed: regular rendering at each
    /// baseline spp (the baseline curve), then with each uniform lattice filter, the thesis'
    /// layers at each, and the full-resolution foveae.
    pub fn baselines(&self) -> Vec<FoveationConfig> {
        let regular = self
            .baseline_spp
            .iter()
            .map(|&s| FoveationConfig::regular(s));
        let filtered = self.baseline_filter_px.iter().flat_map(|&px| {
            self.baseline_spp.iter().map(move |&s| {
                let mut config = FoveationConfig::regular(s);
                config.layers[0].filter_px = px;
                config
            })
        });
        let thesis = self
            .baseline_spp
            .iter()
            .map(|&s| FoveationConfig::thesis().with_spp(s));
        regular
            .chain(filtered)
            .chain(thesis)
            .chain(self.spp_foveae())
            .collect()
    }

    /// A fovea of each radius at each baseline spp above 1, every pixel traced at 1 spp
    /// outside it (`R:1xS bg:1x1`).
    fn spp_foveae(&self) -> impl Iterator<Item = FoveationConfig> + '_ {
        let spp = self.baseline_spp.iter().filter(|&&s| s > 1);
        spp.flat_map(move |&s| {
            self.spp_fovea_radii_deg.iter().map(move |&radius| {
                let mut fovea = FoveationConfig::regular(1).layers[0].clone();
                fovea.radius_deg = Some(radius);
                fovea.spp = s;
                let background = FoveationConfig::regular(1).layers[0].clone();
                self.config(vec![fovea, background])
            })
        })
    }

    /// A random config of the space, valid by construction.
    pub fn random(&self, rng: &mut Rng) -> FoveationConfig {
        loop {
            let inner = rng.below(self.max_inner_layers + 1);
            let mut radii: Vec<usize> = Vec::new();
            while radii.len() < inner.min(self.radii_deg.len()) {
                let r = rng.below(self.radii_deg.len());
                if !radii.contains(&r) {
                    radii.push(r);
                }
            }
            radii.sort_unstable();
            let mut layers = Vec::new();
            let (mut spacing, mut spp) = (0usize, self.spp.len() - 1);
            for k in 0..=inner {
                // Spacing never falls outward, spp never rises; the fovea starts fine.
                spacing = match k {
                    0 => rng.below(2.min(self.spacings.len())),
                    _ => (spacing + rng.below(3)).min(self.spacings.len() - 1),
                };
                spp = rng.below(spp + 1);
                let (denoise, denoise_mar) = self.random_denoise(rng, k, self.spacings[spacing]);
                let denoise_sigma = self.random_sigma(rng, denoise);
                let filter_mar = self.random_filter(rng, self.spacings[spacing]);
                layers.push(Layer {
                    radius_deg: radii.get(k).map(|&r| self.radii_deg[r]),
                    spacing: self.spacings[spacing],
                    spp: self.spp[spp],
                    denoise,
                    filter_mar,
                    filter_px: 0.0,
                    denoise_mar,
                    denoise_sigma,
                    fraction: self.random_fraction(rng, filter_mar),
                });
            }
            let config = self.config(layers);
            if config.validate().is_ok() {
                return config;
            }
        }
    }

    /// Denoising for layer `k` of `spacing`, one time in three: iterations and their acuity
    /// limit (0: none). A full-resolution fovea is denoised only with a limit, which keeps
    /// the gaze sharp. On cornell in motion, two unlimited iterations outside a 10° fovea,
    /// every pixel at 1 spp, gained 0.09 JOD; three limited to 2 minimum angles of resolution
    /// over a regular 1-spp frame gained 0.11. A space without limits draws as before it had
    /// them (a plan from then resumes with the same draws).
    fn random_denoise(&self, rng: &mut Rng, k: usize, spacing: u32) -> (u32, f32) {
        let limits = self.denoise_mar.len() > 1;
        let fovea = spacing == 1 && k == 0;
        if (fovea && !limits) || self.denoise.len() < 2 || rng.below(3) != 0 {
            return (0, 0.0);
        }
        let iterations = self.denoise[1 + rng.below(self.denoise.len() - 1)];
        let limit = match limits {
            true => self.denoise_mar[rng.below(self.denoise_mar.len())],
            false => 0.0,
        };
        match fovea && limit == 0.0 {
            true => (0, 0.0),
            false => (iterations, limit),
        }
    }

    /// The luminance edge-stop of a layer denoised `iterations` times: one of the space's. A
    /// space with only the default draws as before it had the setting.
    fn random_sigma(&self, rng: &mut Rng, iterations: u32) -> f32 {
        match iterations > 0 && self.denoise_sigma.len() > 1 {
            true => self.denoise_sigma[rng.below(self.denoise_sigma.len())],
            false => DEFAULT_DENOISE_SIGMA,
        }
    }

    /// The lattice filter for a layer of `spacing`: only sparse layers, and one time in two.
    fn random_filter(&self, rng: &mut Rng, spacing: u32) -> f32 {
        if spacing == 1 || self.filter_mar.len() < 2 || rng.below(2) != 0 {
            return 0.0;
        }
        self.filter_mar[1 + rng.below(self.filter_mar.len() - 1)]
    }

    /// The fraction of its points a layer traces per frame: all, or one time in three
    /// another of the space's (not with a lattice filter, which smooths traced points only).
    /// A space with only 1 draws as before it had fractions.
    fn random_fraction(&self, rng: &mut Rng, filter_mar: f32) -> u32 {
        if self.fractions.len() < 2 || rng.below(3) != 0 || filter_mar > 0.0 {
            return 1;
        }
        self.fractions[1 + rng.below(self.fractions.len() - 1)]
    }

    /// `parent` changed in one place (a radius, a spacing, an spp, a denoiser, its limit or its
    /// edge-stop, a lattice filter, a layer added or removed), valid; the parent itself when no
    /// change the space allows is valid.
    pub fn mutate(&self, parent: &FoveationConfig, rng: &mut Rng) -> FoveationConfig {
        for _ in 0..64 {
            let mut layers = parent.layers.clone();
            let k = rng.below(layers.len());
            let up = rng.below(2) == 0;
            // A space without edge-stops, denoiser limits or fractions mutates as before it
            // had them.
            let changes = match (
                self.denoise_sigma.len() > 1,
                self.fractions.len() > 1,
                self.denoise_mar.len() > 1,
            ) {
                (true, _, _) => 10,
                (false, true, _) => 9,
                (false, false, true) => 8,
                (false, false, false) => 7,
            };
            match rng.below(changes) {
                0 => {
                    let Some(r) = layers[k].radius_deg else {
                        continue;
                    };
                    let i = self.radii_deg.iter().position(|&x| x >= r).unwrap_or(0);
                    let j = match up {
                        true => (i + 1).min(self.radii_deg.len() - 1),
                        false => i.saturating_sub(1),
                    };
                    layers[k].radius_deg = Some(self.radii_deg[j]);
                }
                1 => layers[k].spacing = step(&self.spacings, layers[k].spacing, up),
                2 => layers[k].spp = step(&self.spp, layers[k].spp, up),
                3 => {
                    layers[k].denoise = step(&self.denoise, layers[k].denoise, up);
                    // An undenoised layer's edge-stop would change only its name.
                    if layers[k].denoise == 0 {
                        layers[k].denoise_sigma = DEFAULT_DENOISE_SIGMA;
                    }
                }
                6 => layers[k].filter_mar = step(&self.filter_mar, layers[k].filter_mar, up),
                7 if layers[k].denoise > 0 => {
                    layers[k].denoise_mar = step(&self.denoise_mar, layers[k].denoise_mar, up)
                }
                8 => layers[k].fraction = step(&self.fractions, layers[k].fraction, up),
                9 if layers[k].denoise > 0 => {
                    layers[k].denoise_sigma = step(&self.denoise_sigma, layers[k].denoise_sigma, up)
                }
                4 if layers.len() <= self.max_inner_layers => {
                    // Split layer k at a radius inside it: the new inner part one spacing finer.
                    let outer = layers[k].radius_deg.unwrap_or(f32::INFINITY);
                    let inner = match k {
                        0 => 0.0,
                        _ => layers[k - 1].radius_deg.unwrap_or(0.0),
                    };
                    let inside: Vec<f32> = (self.radii_deg.iter().copied())
                        .filter(|&r| r > inner && r < outer)
                        .collect();
                    if inside.is_empty() {
                        continue;
                    }
                    let mut split = layers[k].clone();
                    split.radius_deg = Some(inside[rng.below(inside.len())]);
                    split.spacing = step(&self.spacings, split.spacing, false);
                    layers.insert(k, split);
                }
                5 if layers.len() > 1 => {
                    // Merge layer k into the next one out.
                    let k = k.min(layers.len() - 2);
                    layers.remove(k);
                }
                _ => continue,
            }
            let child = self.config(layers);
            if child != *parent && child.validate().is_ok() {
                return child;
            }
        }
        parent.clone()
    }

    fn config(&self, layers: Vec<Layer>) -> FoveationConfig {
        FoveationConfig {
            layers,
            blend_deg: self.blend_deg,
            occlusion_deg: self.occlusion_deg,
        }
    }
}

/// The value next to `v` in the ascending `values`, up or down (the first at least `v` when
/// `v` is not among them), staying at the ends.
fn step<T: PartialOrd + Copy>(values: &[T], v: T, up: bool) -> T {
    let i = values
        .iter()
        .position(|&x| x >= v)
        .unwrap_or(values.len() - 1);
    match up {
        true => values[(i + 1).min(values.len() - 1)],
        false => values[i.saturating_sub(1)],
    }
}

/// A config in one short line, its identity in the tune's files: each layer as
/// `RADIUS:SPACINGxSPP` (`bg` for the background), `dN` for denoiser iterations, `mW` for
/// their acuity limit, `sS` for their luminance edge-stop (when not the default 4), `fM` for
/// an acuity lattice filter, `pP` for a uniform one, `rN` for 1
/// in N points traced per frame, then the occlusion mask; e.g.
/// `6:1x4 10:2x4 20:3x4d1f0.5 bg:4x4f1 occ56`.
pub fn describe(config: &FoveationConfig) -> String {
    let mut parts: Vec<String> = config
        .layers
        .iter()
        .map(|l| {
            let radius = l.radius_deg.map_or("bg".to_string(), |r| format!("{r}"));
            let mut knobs = String::new();
            if l.denoise > 0 {
                knobs += &format!("d{}", l.denoise);
            }
            if l.denoise_mar > 0.0 {
                knobs += &format!("m{}", l.denoise_mar);
            }
            if l.denoise_sigma != DEFAULT_DENOISE_SIGMA {
                knobs += &format!("s{}", l.denoise_sigma);
            }
            if l.filter_mar > 0.0 {
                knobs += &format!("f{}", l.filter_mar);
            }
            if l.filter_px > 0.0 {
                knobs += &format!("p{}", l.filter_px);
            }
            if l.fraction > 1 {
                knobs += &format!("r{}", l.fraction);
            }
            format!("{radius}:{}x{}{knobs}", l.spacing, l.spp)
        })
        .collect();
    if let Some(occ) = config.occlusion_deg {
        parts.push(format!("occ{occ}"));
    }
    if config.layers.len() > 1 {
        parts.push(format!("blend{}", config.blend_deg));
    }
    parts.join(" ")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn random_configs_are_valid_varied_and_reproducible() {
        let space = Space::standard();
        let draw = |seed| {
            let mut rng = Rng::new(seed);
            (0..200).map(|_| space.random(&mut rng)).collect::<Vec<_>>()
        };
        let a = draw(1);
        assert_eq!(a, draw(1));
        assert_ne!(a, draw(2));
        assert!(a.iter().all(|c| c.validate().is_ok()));
        for inner in 0..=space.max_inner_layers {
            assert!(a.iter().any(|c| c.layers.len() == inner + 1), "{inner}");
        }
        assert!(a.iter().any(|c| c.layers.iter().any(|l| l.denoise > 0)));
        // A full-resolution fovea is denoised only with an acuity limit (so its gaze stays
        // sharp); a full-resolution layer outside it may be without.
        assert!(a.iter().all(|c| c.layers[0].spacing > 1
            || c.layers[0].denoise == 0
            || c.layers[0].denoise_mar > 0.0));
        assert!(a
            .iter()
            .any(|c| c.layers[0].spacing == 1 && c.layers[0].denoise_mar > 0.0));
        assert!(a.iter().all(|c| c
            .layers
            .iter()
            .all(|l| l.denoise > 0 || l.denoise_mar == 0.0)));
        assert!(a.iter().any(|c| c
            .layers
            .iter()
            .skip(1)
            .any(|l| l.spacing == 1 && l.denoise > 0)));
        assert!(a
            .iter()
            .any(|c| c.layers.iter().any(|l| l.filter_mar > 0.0)));
        assert!(a
            .iter()
            .all(|c| !c.layers[0].filters() || c.layers[0].spacing > 1));
        assert!(a.iter().all(|c| c.layers[0].spacing <= 2));
        // Fractions at any spacing, never beside a lattice filter.
        for fraction in [2, 4] {
            assert!(a
                .iter()
                .any(|c| c.layers.iter().any(|l| l.fraction == fraction)));
        }
        assert!(a
            .iter()
            .all(|c| c.layers.iter().all(|l| l.fraction == 1 || !l.filters())));
        // Both edge-stops among the denoised layers, the default on the others.
        for sigma in [0.5, 1.0, DEFAULT_DENOISE_SIGMA] {
            assert!(a.iter().any(|c| c
                .layers
                .iter()
                .any(|l| l.denoise > 0 && l.denoise_sigma == sigma)));
        }
        assert!(a.iter().all(|c| c
            .layers
            .iter()
            .all(|l| l.denoise > 0 || l.denoise_sigma == DEFAULT_DENOISE_SIGMA)));
        let distinct: std::collections::HashSet<String> = a.iter().map(describe).collect();
        assert!(distinct.len() > 150, "{}", distinct.len());
    }

    #[test]
    fn a_mutation_changes_one_thing_and_stays_valid() {
        let space = Space::standard();
        let mut rng = Rng::new(5);
        // Two layers and a background: a mutation may add one or merge two.
        let mut parent = FoveationConfig::thesis();
        parent.layers.remove(1);
        let mut layer_counts = std::collections::HashSet::new();
        for _ in 0..200 {
            let child = space.mutate(&parent, &mut rng);
            assert!(child.validate().is_ok());
            assert_ne!(child, parent);
            layer_counts.insert(child.layers.len());
            if child.layers.len() == parent.layers.len() {
                let differing = (child.layers.iter().zip(&parent.layers))
                    .filter(|(c, p)| c != p)
                    .count();
                assert_eq!(differing, 1, "{}", describe(&child));
            }
        }
        assert_eq!(layer_counts.len(), 3, "{layer_counts:?}");
        // A denoised layer's edge-stop is one of the things a mutation may change.
        parent.layers[0].denoise = 3;
        let sigmas: std::collections::HashSet<String> = (0..200)
            .map(|_| space.mutate(&parent, &mut rng))
            .filter(|c| c.layers.len() == parent.layers.len())
            .map(|c| format!("{}", c.layers[0].denoise_sigma))
            .collect();
        assert!(sigmas.contains("1"), "{sigmas:?}");
        // And a layer whose denoiser a mutation turns off keeps no edge-stop of its own.
        parent.layers[0].denoise_sigma = 1.0;
        parent.layers[0].denoise = 1;
        assert!((0..200).all(|_| {
            let child = space.mutate(&parent, &mut rng);
            child.layers.len() != parent.layers.len()
                || child.layers[0].denoise > 0
                || child.layers[0].denoise_sigma == DEFAULT_DENOISE_SIGMA
        }));
    }

    #[test]
    fn full_resolution_foveae_are_baselines_of_the_standard_space_only() {
        let names: Vec<String> = Space::standard().baselines().iter().map(describe).collect();
        let foveae = [
            "20:1x2 bg:1x1",
            "30:1x2 bg:1x1",
            "20:1x4 bg:1x1",
            "30:1x4 bg:1x1",
        ];
        for fovea in foveae {
            let name = format!("{fovea} occ56 blend1");
            assert_eq!(names.iter().filter(|n| **n == name).count(), 1, "{names:?}");
        }
        assert_eq!(names.len(), 9 + 3 + foveae.len());
        assert!(Space::standard()
            .baselines()
            .iter()
            .all(|c| c.validate().is_ok()));
        // A plan written before them reads as a space without them: it resumes with the
        // candidates it had.
        let mut old = serde_json::to_value(Space::standard()).unwrap();
        old.as_object_mut().unwrap().remove("spp_fovea_radii_deg");
        let old: Space = serde_json::from_value(old).unwrap();
        assert_eq!(old.baselines().len(), 9 + 3);
        // And without denoiser limits: it draws none.
        let mut old = serde_json::to_value(Space::standard()).unwrap();
        old.as_object_mut().unwrap().remove("denoise_mar");
        let old: Space = serde_json::from_value(old).unwrap();
        assert_eq!(old.denoise_mar, [0.0]);
        let mut rng = Rng::new(3);
        assert!((0..200).all(|_| old
            .random(&mut rng)
            .layers
            .iter()
            .all(|l| l.denoise_mar == 0.0)));
        // And without fractions: every layer traces every point.
        let mut old = serde_json::to_value(Space::standard()).unwrap();
        old.as_object_mut().unwrap().remove("fractions");
        let old: Space = serde_json::from_value(old).unwrap();
        assert_eq!(old.fractions, [1]);
        assert!((0..200).all(|_| !old.random(&mut rng).fractional()));
        // And without edge-stops: every layer stops at the default.
        let mut old = serde_json::to_value(Space::standard()).unwrap();
        old.as_object_mut().unwrap().remove("denoise_sigma");
        let old: Space = serde_json::from_value(old).unwrap();
        assert_eq!(old.denoise_sigma, [DEFAULT_DENOISE_SIGMA]);
        assert!((0..200).all(|_| old
            .random(&mut rng)
            .layers
            .iter()
            .all(|l| l.denoise_sigma == DEFAULT_DENOISE_SIGMA)));
        assert_eq!(Space::small().baselines().len(), 2 + 2);
    }

    #[test]
    fn descriptions_name_every_knob() {
        let mut config = FoveationConfig::thesis();
        config.layers[2].denoise = 2;
        config.layers[2].filter_mar = 0.5;
        config.layers[3].filter_mar = 1.0;
        (config.layers[0].denoise, config.layers[0].denoise_mar) = (3, 2.0);
        config.layers[0].denoise_sigma = 1.0;
        config.layers[1].fraction = 4;
        assert_eq!(
            describe(&config),
            "6:1x4d3m2s1 10:2x4r4 20:3x4d2f0.5 bg:4x4f1 occ56 blend1"
        );
        let mut regular = FoveationConfig::regular(2);
        assert_eq!(describe(&regular), "bg:1x2");
        regular.layers[0].filter_px = 2.0;
        assert_eq!(describe(&regular), "bg:1x2p2");
    }
}
