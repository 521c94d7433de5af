//! Walking the node tree of the default scene: transforms composed, meshes and materials
//! deduplicated, one instance per node and primitive, the first perspective camera.

use std::collections::HashMap;

use glam::{Mat4, Quat, Vec3, Vec4};
use gltf::json;
use gltf::json::validation::Checked;

use super::lights::world_light;
use super::limits::MAX_COORDINATE;
use super::materials::{convert_material, default_material};
use super::origin::{Origin, Warnings};
use super::primitive::{build_primitive, is_triangles};
use super::textures::TextureLoader;
use crate::scene::tangents::with_generated_tangents;
use crate::scene::{Camera, Instance, Material, Mesh, PunctualLight, SceneError, Texture};

/// The result of walking the node tree.
pub(super) struct Walked {
    pub(super) meshes: Vec<Mesh>,
    pub(super) instances: Vec<Instance>,
    pub(super) materials: Vec<Material>,
    pub(super) textures: Vec<Texture>,
    pub(super) camera: Option<NodeCamera>,
    /// `KHR_lights_punctual` lights of the nodes (those with zero intensity dropped).
    pub(super) lights: Vec<PunctualLight>,
    /// Distinct primitives skipped because they are points or lines.
    pub(super) skipped_primitives: usize,
}

/// A perspective camera and the world transform of its node.
#[derive(Clone, Copy)]
pub(super) struct NodeCamera {
    position: Vec3,
    forward: Vec3,
    up: Vec3,
    yfov: f32,
}

impl NodeCamera {
    pub(super) fn to_camera(self, aspect: f32) -> Camera {
        let half_y = (0.5 * self.yfov).tan();
        let half_x = (half_y * aspect).atan();
        let half_y = half_y.atan();
        Camera {
            position: self.position,
            forward: self.forward,
            up: self.up,
            angle_left: -half_x,
            angle_right: half_x,
            angle_up: half_y,
            angle_down: -half_y,
        }
    }
}

/// Walks the default scene (or the first; or, with no scenes, every root node) depth first,
/// composing transforms, building deduplicated meshes, materials and instances.
/// Images beside a `.gltf` are read from `base_dir` (`None`: not allowed).
pub(super) fn walk(
    document: &gltf::Document,
    buffers: &[Vec<u8>],
    base_dir: Option<&std::path::Path>,
    origin: &Origin,
    warnings: &mut Warnings,
) -> Result<Walked, SceneError> {
    let mut walker = Walker {
        document,
        buffers,
        origin,
        warnings,
        textures: TextureLoader::new(buffers, base_dir),
        walked: Walked {
            meshes: Vec::new(),
            instances: Vec::new(),
            materials: Vec::new(),
            textures: Vec::new(),
            camera: None,
            lights: Vec::new(),
            skipped_primitives: 0,
        },
        mesh_ids: HashMap::new(),
        material_ids: HashMap::new(),
        meshes_by_content: MeshDedup::default(),
    };
    let mut visited = vec![false; document.nodes().len()];
    let mut stack: Vec<(gltf::Node, Mat4)> = roots(document)
        .into_iter()
        .rev()
        .map(|n| (n, Mat4::IDENTITY))
        .collect();
    while let Some((node, parent)) = stack.pop() {
        let label = node_label(&node);
        match visited.get_mut(node.index()) {
            Some(seen) if !*seen => *seen = true,
            _ => {
                return Err(origin.invalid(format!(
                    "{label} is reached twice: the node hierarchy has a cycle or a node with \
                     two parents, which glTF forbids; re-export the file"
                )))
            }
        }
        let world = walker.visit(&node, parent, &label)?;
        let children: Vec<gltf::Node> = node.children().collect();
        stack.extend(children.into_iter().rev().map(|c| (c, world)));
    }
    walker.walked.textures = std::mem::take(&mut walker.textures.textures);
    Ok(walker.walked)
}

/// The nodes the walk starts from: the default scene's (or the first scene's), or, in a file
/// without scenes, every node that is no node's child.
fn roots(document: &gltf::Document) -> Vec<gltf::Node<'_>> {
    if let Some(scene) = document
        .default_scene()
        .or_else(|| document.scenes().next())
    {
        return scene.nodes().collect();
    }
    let mut is_child = vec![false; document.nodes().len()];
    for node in document.nodes() {
        for child in node.children() {
            if let Some(flag) = is_child.get_mut(child.index()) {
                *flag = true;
            }
        }
    }
    document
        .nodes()
        .filter(|n| !is_child.get(n.index()).copied().unwrap_or(true))
        .collect()
}

/// What the walk has built so far, and the maps that let it build each thing once.
struct Walker<'w, 'd> {
    document: &'d gltf::Document,
    buffers: &'d [Vec<u8>],
    origin: &'w Origin<'w>,
    warnings: &'w mut Warnings,
    textures: TextureLoader<'d>,
    walked: Walked,
    /// The accessors a primitive reads → Mesh index, or None when the primitive has no
    /// triangles.
    mesh_ids: HashMap<PrimitiveKey, Option<u32>>,
    /// glTF material index (None: the default material) → Scene material index.
    material_ids: HashMap<Option<usize>, u32>,
    meshes_by_content: MeshDedup,
}

/// What a primitive's mesh is built from: the accessors of POSITION, NORMAL, TEXCOORD_0,
/// TEXCOORD_1 and TANGENT, of its indices, its mode, and whether its material's normal map
/// needs tangents the file does not have. Primitives with equal keys are one mesh.
#[derive(Clone, Copy, PartialEq, Eq, Hash)]
struct PrimitiveKey {
    attributes: [Option<usize>; 5],
    indices: Option<usize>,
    mode: u32,
    generates_tangents: bool,
}

impl Walker<'_, '_> {
    /// Adds one node's camera and mesh instances; returns its world transform.
    fn visit(&mut self, node: &gltf::Node, parent: Mat4, label: &str) -> Result<Mat4, SceneError> {
        let origin = self.origin;
        let world =
            parent * local_transform(node).map_err(|p| origin.invalid(format!("{label}: {p}")))?;
        if !world.is_finite() {
            return Err(origin.invalid(format!(
                "{label}: its world transform is not finite (NaN or ±∞); fix the node transforms"
            )));
        }
        if let Some(camera) = node.camera() {
            self.camera(&camera, world, label)?;
        }
        if let Some(light) = node.light() {
            let name = light
                .name()
                .map(|n| format!(" ('{n}')"))
                .unwrap_or_default();
            let light = world_light(&light, world).map_err(|p| {
                origin.invalid(format!("{label}, light #{}{name}: {p}", light.index()))
            })?;
            if light.intensity.max_element() > 0.0 {
                self.walked.lights.push(light);
            } else {
                self.warnings
                    .add("punctual lights of zero intensity (they emit nothing)");
            }
        }
        if let Some(mesh) = node.mesh() {
            for primitive in mesh.primitives() {
                self.instance(&mesh, &primitive, world, label)?;
            }
        }
        Ok(world)
    }

    /// Keeps the first perspective camera; notes orthographic ones.
    fn camera(
        &mut self,
        camera: &gltf::Camera,
        world: Mat4,
        label: &str,
    ) -> Result<(), SceneError> {
        let origin = self.origin;
        let json_camera = self.document.as_json().cameras.get(camera.index());
        match json_camera.map(|c| (&c.type_, c.perspective.as_ref())) {
            Some((Checked::Valid(json::camera::Type::Perspective), Some(p))) => {
                if self.walked.camera.is_none() {
                    self.walked.camera = Some(node_camera(world, p.yfov).map_err(|p| {
                        origin.invalid(format!("{label}, camera #{}: {p}", camera.index()))
                    })?);
                }
            }
            Some((Checked::Valid(json::camera::Type::Orthographic), _)) => self
                .warnings
                .add("orthographic cameras (only perspective cameras are used)"),
            _ => {
                return Err(origin.invalid(format!(
                    "camera #{} has no data for its projection type; re-export the file",
                    camera.index()
                )))
            }
        }
        Ok(())
    }

    /// One instance of a primitive at `world`, its mesh and material built on first use.
    fn instance(
        &mut self,
        mesh: &gltf::Mesh,
        primitive: &gltf::Primitive,
        world: Mat4,
        label: &str,
    ) -> Result<(), SceneError> {
        let Some(mesh_id) = self.mesh_id(mesh, primitive)? else {
            return Ok(());
        };
        let reach = world_reach(self.meshes_by_content.reach(mesh_id), world);
        if !reach.is_finite() || reach.max_element() > MAX_COORDINATE {
            return Err(self.origin.invalid(format!(
                "{label}: it places mesh #{} where its vertices reach coordinates up to \
                 {:e}, beyond ±{MAX_COORDINATE:e} (where f32 ray arithmetic \
                 overflows); the node transforms or the export scale are wrong",
                mesh.index(),
                reach.max_element()
            )));
        }
        let material_id = self.material_id(&primitive.material())?;
        self.walked.instances.push(Instance {
            mesh: mesh_id,
            material: material_id,
            transform: world,
        });
        Ok(())
    }

    /// The scene mesh of a primitive (`None`: it has no triangles). Primitives that read the
    /// same accessors in the same mode are one mesh, and equal geometry is stored once.
    fn mesh_id(
        &mut self,
        mesh: &gltf::Mesh,
        primitive: &gltf::Primitive,
    ) -> Result<Option<u32>, SceneError> {
        let accessor = |semantic: gltf::Semantic| primitive.get(&semantic).map(|a| a.index());
        let tangents = accessor(gltf::Semantic::Tangents);
        let normal_mapped = primitive.material().normal_texture().is_some();
        let key = PrimitiveKey {
            attributes: [
                accessor(gltf::Semantic::Positions),
                accessor(gltf::Semantic::Normals),
                accessor(gltf::Semantic::TexCoords(0)),
                accessor(gltf::Semantic::TexCoords(1)),
                tangents,
            ],
            indices: primitive.indices().map(|a| a.index()),
            mode: primitive.mode().as_gl_enum(),
            generates_tangents: normal_mapped && tangents.is_none(),
        };
        if let Some(&id) = self.mesh_ids.get(&key) {
            return Ok(id);
        }
        let mut built = build_primitive(mesh, primitive, self.buffers, self.warnings)
            .map_err(|p| self.origin.invalid(p))?;
        if key.generates_tangents {
            built = built.map(|m| with_generated_tangents(&m).unwrap_or(m));
        }
        let id = match built {
            Some(m) => Some(self.meshes_by_content.add(m, &mut self.walked.meshes)),
            None => {
                if !is_triangles(primitive.mode()) {
                    self.walked.skipped_primitives += 1;
                }
                None
            }
        };
        self.mesh_ids.insert(key, id);
        Ok(id)
    }

    /// The scene material of a glTF material (the default one for `None`); materials with equal
    /// values are one material.
    fn material_id(&mut self, gltf_material: &gltf::Material) -> Result<u32, SceneError> {
        if let Some(&id) = self.material_ids.get(&gltf_material.index()) {
            return Ok(id);
        }
        let material = match gltf_material.index() {
            Some(_) => convert_material(
                gltf_material,
                &mut self.textures,
                self.origin,
                self.warnings,
            )?,
            None => default_material(),
        };
        // Factors are finite (convert_material checks them), so equality is well defined.
        let materials = &mut self.walked.materials;
        let id = match materials.iter().position(|m| *m == material) {
            Some(i) => i as u32,
            None => {
                materials.push(material);
                (materials.len() - 1) as u32
            }
        };
        self.material_ids.insert(gltf_material.index(), id);
        Ok(id)
    }
}

fn node_label(node: &gltf::Node) -> String {
    match node.name() {
        Some(name) => format!("node '{name}' (#{})", node.index()),
        None => format!("node #{}", node.index()),
    }
}

/// The node's local transform (matrix or TRS). A matrix must be affine (glTF requires it to be
/// decomposable into TRS); a rotation quaternion is normalised (exporters round it).
fn local_transform(node: &gltf::Node) -> Result<Mat4, String> {
    match node.transform() {
        gltf::scene::Transform::Matrix { matrix } => {
            let m = Mat4::from_cols_array_2d(&matrix);
            if !m.is_finite() {
                return Err("its matrix is not finite (NaN or ±∞)".into());
            }
            if !m.row(3).abs_diff_eq(Vec4::W, 1e-6) {
                return Err(
                    "its matrix is projective (last row is not 0 0 0 1); glTF node \
                            matrices must be affine"
                        .into(),
                );
            }
            Ok(m)
        }
        gltf::scene::Transform::Decomposed {
            translation,
            rotation,
            scale,
        } => {
            let (t, r, s) = (
                Vec3::from(translation),
                Quat::from_array(rotation),
                Vec3::from(scale),
            );
            if !(t.is_finite() && r.is_finite() && s.is_finite()) {
                return Err("its translation, rotation or scale is not finite (NaN or ±∞)".into());
            }
            let length = r.length();
            if length < 1e-6 {
                return Err("its rotation quaternion has zero length".into());
            }
            Ok(Mat4::from_scale_rotation_translation(s, r / length, t))
        }
    }
}

/// Adds meshes to a scene's list, reusing an equal mesh (same positions, triangles and shading attributes) when
/// there is one, so identical geometry is stored and BVH-built once. Also keeps each mesh's
/// reach (the largest magnitude per axis of its vertices, object space) for [`world_reach`].
#[derive(Default)]
struct MeshDedup {
    /// Hash of positions and triangles → indices of the meshes with that hash.
    by_hash: HashMap<u64, Vec<u32>>,
    reaches: Vec<Vec3>,
}

impl MeshDedup {
    fn add(&mut self, mesh: Mesh, meshes: &mut Vec<Mesh>) -> u32 {
        use std::hash::{Hash, Hasher};
        let mut hasher = std::collections::hash_map::DefaultHasher::new();
        for p in &mesh.positions {
            p.to_array().map(f32::to_bits).hash(&mut hasher);
        }
        mesh.indices.hash(&mut hasher);
        let same = self.by_hash.entry(hasher.finish()).or_default();
        if let Some(&id) = same.iter().find(|&&id| {
            meshes.get(id as usize).is_some_and(|m| {
                m.positions == mesh.positions
                    && m.indices == mesh.indices
                    && m.shading == mesh.shading
            })
        }) {
            return id;
        }
        let id = meshes.len() as u32;
        same.push(id);
        self.reaches.push(
            mesh.positions
                .iter()
                .fold(Vec3::ZERO, |r, p| r.max(p.abs())),
        );
        meshes.push(mesh);
        id
    }

    fn reach(&self, id: u32) -> Vec3 {
        self.reaches.get(id as usize).copied().unwrap_or(Vec3::ZERO)
    }
}

/// An upper bound, per world axis, of `|world · p|` over vertices whose per-axis magnitudes
/// are at most `r` ([`MeshDedup::reach`]): interval arithmetic, so it costs nothing per instance
/// vertex, and it is finite only if every transformed vertex is.
fn world_reach(r: Vec3, world: Mat4) -> Vec3 {
    let axis = |v: Vec4| v.truncate().abs();
    axis(world.x_axis) * r.x
        + axis(world.y_axis) * r.y
        + axis(world.z_axis) * r.z
        + axis(world.w_axis)
}

/// A camera at the node's world transform looking down its −Z with +Y up.
fn node_camera(world: Mat4, yfov: f32) -> Result<NodeCamera, String> {
    if !(yfov.is_finite() && yfov > 0.0 && yfov < std::f32::consts::PI) {
        return Err(format!(
            "its vertical field of view {yfov} rad is not in (0, π)"
        ));
    }
    let position = world.transform_point3(Vec3::ZERO);
    if !position.is_finite() || position.abs().max_element() > MAX_COORDINATE {
        return Err(format!(
            "it is at a coordinate of {:e}, beyond ±{MAX_COORDINATE:e} (where f32 ray \
             arithmetic overflows); fix the node transforms",
            position.abs().max_element()
        ));
    }
    let forward = world.transform_vector3(Vec3::NEG_Z).normalize_or_zero();
    let up = world.transform_vector3(Vec3::Y);
    // Non-uniform scale or shear can tilt +Y off the image plane: re-orthogonalise.
    let up = (up - forward * up.dot(forward)).normalize_or_zero();
    if forward == Vec3::ZERO || up == Vec3::ZERO {
        return Err("its node transform is degenerate (zero scale)".into());
    }
    Ok(NodeCamera {
        position,
        forward,
        up,
        yfov,
    })
}
