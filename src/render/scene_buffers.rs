//! The scene on the GPU: its BVHs and arrays uploaded once, after a check that they fit the
//! device, and the bindings a pass that traces rays declares to read them.

use super::counters::FrameCounters;
use super::graph::Pass;
use super::scene_textures;
use super::settings::Traversal;
use super::RenderError;
use crate::gpu::{
    AccelStructures, Bound, Buffer, GpuContext, PlannedAllocation, TexelView, TextureSet,
};
use crate::scene::gpu_layout::GpuScene;
use crate::scene::{Scene, SceneFeatures};
use crate::shader_layout::*;
use std::sync::Arc;

/// Static scene data on the GPU, one buffer per binding.
pub struct SceneBuffers {
    // The scene's arrays are read through texel views of their buffers (see TexelView).
    /// Every BLAS's nodes, then the TLAS's (GpuSceneInfo::tlas_root).
    nodes: TexelView,
    triangles: TexelView,
    /// GpuScene::shading (one empty element when the scene has none).
    shading: TexelView,
    objects: TexelView,
    materials: TexelView,
    emitters: TexelView,
    /// GpuScene::environment (one empty element without an environment map).
    environment: TexelView,
    _storage: [Buffer; 7],
    info: Buffer,
    /// The textures glTF materials sample (none for most scenes).
    textures: TextureSet,
    /// The same scene for ray queries, where the context has them.
    pub accel: Option<AccelStructures>,
    /// What the scene has, for specializing the shaders.
    pub features: SceneFeatures,
    /// The scene as uploaded ([`GpuScene::fingerprint`]).
    pub fingerprint: u64,
    /// What the scene holds in device-local memory (acceleration structures aside).
    pub memory: SceneMemory,
}

/// Device-local bytes of a scene: its arrays (BVH nodes, triangles, shading, objects,
/// materials, emitters, the environment map with its sampling table) and its textures (every
/// mip level).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SceneMemory {
    pub buffers: u64,
    pub textures: u64,
}

fn device_bytes(plan: &[PlannedAllocation]) -> u64 {
    plan.iter()
        .filter(|a| !a.host_visible)
        .map(|a| a.bytes)
        .sum()
}

impl SceneBuffers {
    /// Builds the BVHs, checks that the scene fits the device, and uploads it.
    pub fn upload(ctx: &Arc<GpuContext>, scene: &Scene) -> Result<Self, RenderError> {
        let gpu = GpuScene::build(scene)?;
        scene_textures::check_sizes(&scene.textures, ctx.info.max_image_dimension_2d)
            .map_err(RenderError::Settings)?;
        let arrays = arrays_plan(&gpu);
        let textures = scene_textures::allocations(&scene.textures);
        let memory = SceneMemory {
            buffers: device_bytes(&arrays),
            textures: device_bytes(&textures),
        };
        let plan = [arrays, FrameCounters::allocations(), textures].concat();
        ctx.check_memory(
            &format!("scene '{}'", scene.name),
            &plan,
            "simplify the scene (fewer or smaller meshes and textures, a smaller --env)",
        )?;
        let upload = |name: &str, bytes: &[u8]| Buffer::with_data(ctx, name, bytes);
        let nodes = upload("bvh nodes", bytemuck::cast_slice(&gpu.nodes()))?;
        let triangles = upload("triangles", bytemuck::cast_slice(&gpu.triangles))?;
        let shading = upload("triangle shading", bytemuck::cast_slice(&gpu.shading))?;
        let objects = upload("objects", bytemuck::cast_slice(&gpu.objects))?;
        let materials = upload("materials", bytemuck::cast_slice(&gpu.materials))?;
        let emitters = upload("emitters", bytemuck::cast_slice(&gpu.emitters))?;
        let environment = upload("environment", bytemuck::cast_slice(&gpu.environment))?;
        let accel = match ctx.info.ray_query {
            Some(_) => Some(AccelStructures::build(
                ctx,
                &gpu.triangles,
                &gpu.accel_objects(),
            )?),
            None => None,
        };
        Ok(Self {
            nodes: TexelView::new(&nodes, "bvh nodes")?,
            triangles: TexelView::new(&triangles, "triangles")?,
            shading: TexelView::new(&shading, "triangle shading")?,
            objects: TexelView::new(&objects, "objects")?,
            materials: TexelView::new(&materials, "materials")?,
            emitters: TexelView::new(&emitters, "emitters")?,
            environment: TexelView::new(&environment, "environment")?,
            _storage: [
                nodes,
                triangles,
                shading,
                objects,
                materials,
                emitters,
                environment,
            ],
            info: upload("scene info", bytemuck::bytes_of(&gpu.info))?,
            textures: TextureSet::upload(ctx, &scene_textures::uploads(&scene.textures))?,
            accel,
            features: gpu.features,
            fingerprint: gpu.fingerprint(),
            memory,
        })
    }

    /// Declares that `pass` traces rays through the scene with `traversal`: the arrays it
    /// reads, and the BVH nodes (software) or the TLAS (ray queries).
    pub fn declare<'g, 'a, 'r>(
        &'r self,
        pass: Pass<'g, 'a, 'r>,
        traversal: Traversal,
    ) -> Pass<'g, 'a, 'r> {
        let pass = pass
            .reads(BINDING_TRIANGLES, &self.triangles)
            .reads(BINDING_SHADING, &self.shading)
            .reads(BINDING_OBJECTS, &self.objects)
            .reads(BINDING_MATERIALS, &self.materials)
            .reads(BINDING_EMITTERS, &self.emitters)
            .reads(BINDING_ENVIRONMENT, &self.environment)
            .reads(BINDING_SCENE_INFO, &self.info)
            .reads(BINDING_TEXTURES, Bound::Textures(&self.textures));
        match (traversal, &self.accel) {
            (Traversal::RayQuery, Some(accel)) => pass.reads(BINDING_TLAS, Bound::Tlas(accel)),
            _ => pass.reads(BINDING_NODES, &self.nodes),
        }
    }
}

impl SceneBuffers {
    /// Declares that `pass` reads the scene's materials (and nothing else of it).
    pub fn declare_materials<'g, 'a, 'r>(&'r self, pass: Pass<'g, 'a, 'r>) -> Pass<'g, 'a, 'r> {
        pass.reads(BINDING_MATERIALS, &self.materials)
    }
}

/// The allocations [`SceneBuffers::upload`] makes for a scene's arrays (its textures and the
/// renderer's counters are planned beside them), for the memory check before them.
fn arrays_plan(gpu: &GpuScene) -> Vec<PlannedAllocation> {
    use std::mem::size_of_val;
    // Buffer::new gives an empty array one 16-byte element.
    let bytes = |b: usize| (b as u64).max(16);
    let buffers = [
        (
            "bvh nodes",
            bytes(size_of_val(gpu.blas_nodes.as_slice()) + size_of_val(gpu.tlas_nodes.as_slice())),
        ),
        ("triangles", bytes(size_of_val(gpu.triangles.as_slice()))),
        (
            "triangle shading",
            bytes(size_of_val(gpu.shading.as_slice())),
        ),
        ("objects", bytes(size_of_val(gpu.objects.as_slice()))),
        ("materials", bytes(size_of_val(gpu.materials.as_slice()))),
        ("emitters", bytes(size_of_val(gpu.emitters.as_slice()))),
        (
            "environment",
            bytes(size_of_val(gpu.environment.as_slice())),
        ),
        ("scene info", bytes(size_of_val(&gpu.info))),
    ];
    let largest = buffers.iter().map(|b| b.1).max().unwrap_or(0);
    let mut plan: Vec<PlannedAllocation> = buffers
        .iter()
        .map(|(name, b)| PlannedAllocation::storage(name, *b))
        .collect();
    // Each buffer is uploaded through its own staging buffer, freed before the next.
    plan.push(PlannedAllocation::host("upload staging", largest, false));
    plan
}
