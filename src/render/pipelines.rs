//! The renderer's compute pipelines, made on first use: the trace specialised per scene,
//! integrator, depth and traversal (and whether it profiles or keeps surfaces for the
//! history), the other frame passes once each, the ray-cast probe per traversal and the BRDF
//! probe.

use super::passes::FramePipelines;
use super::settings::{RenderSettings, Traversal};
use super::RenderError;
use crate::gpu::{shaders, ComputePipeline, GpuContext, PipelineLayout};
use crate::scene::SceneFeatures;
use crate::shader_layout::*;
use std::collections::HashMap;
use std::sync::Arc;

/// What a trace pipeline is specialised for, beyond the scene.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct TraceKey {
    /// Integrator::id.
    pub integrator: u32,
    pub max_bounces: u32,
    /// Counts its traversal's work (SPEC_PROFILE; software traversal only).
    pub profile: bool,
    pub traversal: Traversal,
    /// Also writes every lattice point's surface, for the temporal history.
    pub keeps_surfaces: bool,
    /// Sampler::id.
    pub sampler: u32,
    /// Some layer has several lanes per point (SPEC_TRACE_SHARES: the lanes' sums meet in
    /// shared memory).
    pub shares_lanes: bool,
}

impl TraceKey {
    pub fn new(
        settings: &RenderSettings,
        profile: bool,
        traversal: Traversal,
        history: bool,
        shares_lanes: bool,
    ) -> Self {
        Self {
            integrator: settings.integrator.id(),
            max_bounces: settings.max_bounces,
            profile,
            traversal,
            keeps_surfaces: history,
            sampler: settings.sampler.id(),
            shares_lanes,
        }
    }

    fn spirv(&self) -> &'static [u8] {
        match (self.traversal, self.keeps_surfaces) {
            (Traversal::Software, false) => shaders::TRACE,
            (Traversal::RayQuery, false) => shaders::TRACE_RQ,
            (Traversal::Software, true) => shaders::TRACE_SURFACES,
            (Traversal::RayQuery, true) => shaders::TRACE_RQ_SURFACES,
        }
    }
}

/// A pass made once: plan, dispatch sizes, the fill (without and with history), lattice
/// filter, resolve, temporal, denoise.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
enum Fixed {
    Plan,
    DispatchSizes,
    Fill,
    FillSurfaces,
    LatticeFilter,
    Resolve,
    Temporal,
    Denoise,
}

impl Fixed {
    fn shader(self) -> (&'static str, &'static [u8]) {
        match self {
            Fixed::Plan => ("plan", shaders::PLAN),
            Fixed::DispatchSizes => ("dispatch sizes", shaders::PLAN_ARGS),
            Fixed::Fill => ("lattice fill", shaders::LATTICE_FILL),
            Fixed::FillSurfaces => ("lattice fill", shaders::LATTICE_FILL_SURFACES),
            Fixed::LatticeFilter => ("lattice filter", shaders::LATTICE_FILTER),
            Fixed::Resolve => ("resolve", shaders::RESOLVE),
            Fixed::Temporal => ("temporal", shaders::TEMPORAL),
            Fixed::Denoise => ("denoise", shaders::DENOISE),
        }
    }
}

pub struct Pipelines {
    trace: HashMap<TraceKey, ComputePipeline>,
    fixed: HashMap<Fixed, ComputePipeline>,
    raycast: HashMap<Traversal, ComputePipeline>,
    brdf_probe: Option<ComputePipeline>,
    features: SceneFeatures,
    /// Every pipeline's layout (one descriptor-set layout for all of shared.h's bindings).
    pub layout: PipelineLayout,
    ctx: Arc<GpuContext>,
}

impl Pipelines {
    pub fn new(ctx: &Arc<GpuContext>, features: SceneFeatures) -> Result<Self, RenderError> {
        Ok(Self {
            trace: HashMap::new(),
            fixed: HashMap::new(),
            raycast: HashMap::new(),
            brdf_probe: None,
            features,
            layout: PipelineLayout::new(ctx)?,
            ctx: ctx.clone(),
        })
    }

    /// The scene's features and the integrator's choices as specialization constants.
    fn specialization(&self, integrator: u32, max_bounces: u32) -> Vec<(u32, u32)> {
        let f = self.features;
        vec![
            (SPEC_HAS_TRIANGLES, f.triangles as u32),
            (SPEC_HAS_BOXES, f.boxes as u32),
            (SPEC_HAS_SPHERES, f.spheres as u32),
            (SPEC_HAS_SPECULAR, f.specular as u32),
            (SPEC_HAS_EMITTERS, f.emitters as u32),
            (SPEC_HAS_SHADING, f.shading as u32),
            (SPEC_HAS_METALLIC_ROUGHNESS, f.metallic_roughness as u32),
            (SPEC_HAS_TEXTURES, f.textures as u32),
            (SPEC_HAS_CUTOUTS, f.cutouts as u32),
            (SPEC_HAS_SINGLE_SIDED, f.single_sided as u32),
            (SPEC_HAS_ENV_MAP, f.env_map as u32),
            (SPEC_MAX_BOUNCES, max_bounces),
            (SPEC_INTEGRATOR, integrator),
        ]
    }

    /// Makes the pipelines a frame of `trace` needs (with history: lattice filter, temporal
    /// and denoise).
    pub fn ensure(&mut self, trace: TraceKey) -> Result<(), RenderError> {
        if trace.profile && trace.traversal == Traversal::RayQuery {
            return Err(RenderError::Settings(
                "the traversal profile counts the software traversal's work (the driver's \
                 ray queries have no counters of ours): use --traversal software with it"
                    .into(),
            ));
        }
        if !self.trace.contains_key(&trace) {
            let mut spec = self.specialization(trace.integrator, trace.max_bounces);
            spec.push((SPEC_PROFILE, trace.profile as u32));
            spec.push((SPEC_SAMPLER, trace.sampler));
            spec.push((SPEC_TRACE_SHARES, trace.shares_lanes as u32));
            let p = ComputePipeline::new(&self.ctx, &self.layout, "trace", trace.spirv(), &spec)?;
            self.trace.insert(trace, p);
        }
        let mut wanted = vec![Fixed::Plan, Fixed::DispatchSizes, Fixed::Resolve];
        match trace.keeps_surfaces {
            true => wanted.extend([
                Fixed::FillSurfaces,
                Fixed::LatticeFilter,
                Fixed::Temporal,
                Fixed::Denoise,
            ]),
            false => wanted.push(Fixed::Fill),
        }
        for pass in wanted {
            if !self.fixed.contains_key(&pass) {
                let (name, spirv) = pass.shader();
                let p = ComputePipeline::new(&self.ctx, &self.layout, name, spirv, &[])?;
                self.fixed.insert(pass, p);
            }
        }
        Ok(())
    }

    /// A frame's pipelines (made by `ensure`): the fill when a layer is `fractional`; with
    /// `history`, temporal, the lattice filter when `filters`, and denoise when a layer asks
    /// for `denoise_iterations` > 0; without, a trace and a fill that keep no surfaces.
    pub fn frame(
        &self,
        trace: TraceKey,
        history: bool,
        fractional: bool,
        filters: bool,
        denoise_iterations: u32,
    ) -> FramePipelines<'_> {
        let fixed = |pass| &self.fixed[&pass];
        let fill = match history {
            true => Fixed::FillSurfaces,
            false => Fixed::Fill,
        };
        FramePipelines {
            plan: fixed(Fixed::Plan),
            plan_args: fixed(Fixed::DispatchSizes),
            trace: &self.trace[&trace],
            fill: fractional.then(|| fixed(fill)),
            lattice_filter: (history && filters).then(|| fixed(Fixed::LatticeFilter)),
            resolve: fixed(Fixed::Resolve),
            temporal: history.then(|| fixed(Fixed::Temporal)),
            denoise: (history && denoise_iterations > 0)
                .then(|| (fixed(Fixed::Denoise), denoise_iterations)),
        }
    }

    /// Makes the ray-cast probe's pipeline for `traversal`.
    pub fn ensure_raycast(&mut self, traversal: Traversal) -> Result<(), RenderError> {
        if !self.raycast.contains_key(&traversal) {
            let spec = self.specialization(INTEGRATOR_PT, 0);
            let spirv = match traversal {
                Traversal::Software => shaders::RAYCAST,
                Traversal::RayQuery => shaders::RAYCAST_RQ,
            };
            let p = ComputePipeline::new(&self.ctx, &self.layout, "raycast", spirv, &spec)?;
            self.raycast.insert(traversal, p);
        }
        Ok(())
    }

    /// The ray-cast probe's pipeline for `traversal` (made by `ensure_raycast`).
    pub fn raycast(&self, traversal: Traversal) -> &ComputePipeline {
        &self.raycast[&traversal]
    }

    /// Makes the BRDF probe's pipeline, and gives it with the layout.
    pub fn brdf_probe(&mut self) -> Result<(&PipelineLayout, &ComputePipeline), RenderError> {
        if self.brdf_probe.is_none() {
            let spec = self.specialization(INTEGRATOR_PT, 0);
            let spirv = shaders::BRDF_PROBE;
            let p = ComputePipeline::new(&self.ctx, &self.layout, "brdf probe", spirv, &spec)?;
            self.brdf_probe = Some(p);
        }
        let pipeline = self.brdf_probe.as_ref().expect("made above");
        Ok((&self.layout, pipeline))
    }
}
