//! The renderer-independent scene description: what a built-in scene or a glTF file becomes.
//! Everything here is in world units (metres by convention), right-handed, Y up.

use glam::{Mat4, Vec2, Vec3, Vec4};

/// How a surface reflects and emits light: the thesis' model, which the built-in scenes keep
/// so its results stay reproducible, or glTF 2.0's metallic-roughness model, which every glTF
/// file's materials become.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Material {
    Thesis(ThesisMaterial),
    MetallicRoughness(MetallicRoughness),
}

/// A material of the thesis' BRDF (eqs. 3.7–3.8): Lambert `k_d / π` plus modified Phong
/// `k_s (α+2)/(2π) cos^α θ_r`. `alpha == f32::INFINITY` is a perfect mirror.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ThesisMaterial {
    pub kd: Vec3,
    pub ks: Vec3,
    /// Phong exponent α ≥ 0; `f32::INFINITY` means a perfect mirror.
    pub alpha: f32,
    /// Emitted radiance (W·sr⁻¹·m⁻²); one-sided (front face) on triangles, two-sided on
    /// analytic boxes and spheres.
    pub emission: Vec3,
}

/// glTF 2.0's metallic-roughness material (the specification's Appendix B): a GGX specular
/// lobe over a Lambertian base for dielectrics, coloured specular for metals, mixed by
/// `metallic`. Factors are in `[0, 1]`; a texture multiplies its factor.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MetallicRoughness {
    /// `baseColorFactor`'s RGB, linear.
    pub base_color: Vec3,
    pub metallic: f32,
    /// Perceptual roughness; the GGX width is its square.
    pub roughness: f32,
    /// Emitted radiance: `emissiveFactor × KHR_materials_emissive_strength`.
    pub emission: Vec3,
    pub textures: MaterialTextures,
    /// Which parts of the surface rays meet: alpha and faces.
    pub coverage: Coverage,
}

/// Which parts of a surface are there for rays: glTF's `alphaMode`, `alphaCutoff` and
/// `doubleSided` (glTF 2.0, 3.9.4 and 3.9.5). Every ray sees them the same way: camera,
/// bounce and shadow rays, in both traversals.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Coverage {
    /// `baseColorFactor`'s alpha; the base colour texture's alpha multiplies it.
    pub alpha: f32,
    pub mode: AlphaMode,
    /// Both faces are there. A single-sided surface is invisible from behind (glTF's back-face
    /// culling: its front face winds counter-clockwise, its back face is not there).
    pub double_sided: bool,
}

/// How a surface's alpha covers it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum AlphaMode {
    /// Alpha is ignored.
    Opaque,
    /// Present where alpha ≥ `cutoff`, absent elsewhere.
    Mask { cutoff: f32 },
    /// Present with probability alpha (stochastic transparency: a ray passes through with
    /// probability 1 − alpha, which averages to alpha blending over samples).
    Blend,
}

impl Coverage {
    /// glTF's default: opaque and single-sided.
    pub const GLTF_DEFAULT: Self = Self {
        alpha: 1.0,
        mode: AlphaMode::Opaque,
        double_sided: false,
    };
    /// Opaque from both sides: every thesis material, and materials made in code.
    pub const SOLID: Self = Self {
        alpha: 1.0,
        mode: AlphaMode::Opaque,
        double_sided: true,
    };

    /// Alpha decides, per point, whether the surface is there (MASK or BLEND).
    pub fn cuts_out(&self) -> bool {
        self.mode != AlphaMode::Opaque
    }
}

impl MetallicRoughness {
    /// glTF's default material (every property at its default): white, metallic 1, roughness 1.
    pub const GLTF_DEFAULT: Self = Self {
        base_color: Vec3::ONE,
        metallic: 1.0,
        roughness: 1.0,
        emission: Vec3::ZERO,
        textures: MaterialTextures::NONE,
        coverage: Coverage::GLTF_DEFAULT,
    };

    /// A material of factors alone, opaque from both sides.
    pub fn factors(base_color: Vec3, metallic: f32, roughness: f32, emission: Vec3) -> Self {
        Self {
            base_color,
            metallic,
            roughness,
            emission,
            textures: MaterialTextures::NONE,
            coverage: Coverage::SOLID,
        }
    }
}

/// The textures a metallic-roughness material samples, each multiplying its factor.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MaterialTextures {
    /// RGB × `base_color` (sRGB-encoded texels).
    pub base_color: Option<TextureRef>,
    /// B × `metallic`, G × `roughness` (linear texels).
    pub metallic_roughness: Option<TextureRef>,
    /// RGB × `emission` (sRGB-encoded texels).
    pub emissive: Option<TextureRef>,
    /// Tangent-space normals (linear texels), x and y × `normal_scale`.
    pub normal: Option<TextureRef>,
    /// glTF's `normalTexture.scale`.
    pub normal_scale: f32,
}

impl Default for MaterialTextures {
    fn default() -> Self {
        Self::NONE
    }
}

impl MaterialTextures {
    pub const NONE: Self = Self {
        base_color: None,
        metallic_roughness: None,
        emissive: None,
        normal: None,
        normal_scale: 1.0,
    };

    /// Every slot that holds a texture.
    pub fn iter(&self) -> impl Iterator<Item = &TextureRef> {
        [
            &self.base_color,
            &self.metallic_roughness,
            &self.emissive,
            &self.normal,
        ]
        .into_iter()
        .flatten()
    }
}

/// A material's use of a texture: which one, read with which texture coordinates, moved by
/// `KHR_texture_transform`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TextureRef {
    /// Index into [`Scene::textures`].
    pub texture: u32,
    /// `TEXCOORD_n`: 0 or 1.
    pub texcoord: u32,
    /// The texture transform as the rows of a 2×3 matrix: the lookup is at
    /// `(row0 · (u, v, 1), row1 · (u, v, 1))`. Identity without `KHR_texture_transform`.
    pub transform: [[f32; 3]; 2],
}

impl TextureRef {
    pub const IDENTITY: [[f32; 3]; 2] = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
}

/// How a texture's texels encode their values.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum TexelEncoding {
    /// Colours (base colour, emissive): sRGB-encoded, decoded to linear by the sampler.
    Srgb,
    /// Data (metallic-roughness): read as stored.
    Linear,
}

/// How a texture coordinate outside [0, 1] is brought back (glTF's sampler wrap modes).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Wrap {
    Repeat,
    MirroredRepeat,
    ClampToEdge,
}

/// A glTF sampler: wrap modes and filters. Minification with mipmaps picks the level by the
/// footprint (ray cones); `mipmaps: false` reads level 0 only.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct TextureSampler {
    pub wrap_u: Wrap,
    pub wrap_v: Wrap,
    /// Bilinear (true) or nearest texel when magnifying.
    pub mag_linear: bool,
    /// Bilinear (true) or nearest texel when minifying.
    pub min_linear: bool,
    /// Minification reads the mip chain (glTF's *_MIPMAP_* filters and the default).
    pub mipmaps: bool,
}

impl TextureSampler {
    /// glTF's default when a texture names no sampler: repeat, filtering left to the
    /// renderer (bilinear, trilinear with mipmaps).
    pub const DEFAULT: Self = Self {
        wrap_u: Wrap::Repeat,
        wrap_v: Wrap::Repeat,
        mag_linear: true,
        min_linear: true,
        mipmaps: true,
    };
}

/// An image a material samples, decoded: RGBA, 8 bits per channel, rows from the top (glTF's
/// texture coordinate (0, 0) is the first texel).
#[derive(Clone, Debug, PartialEq)]
pub struct Texture {
    /// What the file calls it (for messages).
    pub name: String,
    pub width: u32,
    pub height: u32,
    pub rgba8: Vec<u8>,
    pub encoding: TexelEncoding,
    pub sampler: TextureSampler,
}

impl Material {
    pub fn diffuse(kd: Vec3) -> Self {
        Self::Thesis(ThesisMaterial {
            kd,
            ks: Vec3::ZERO,
            alpha: 1.0,
            emission: Vec3::ZERO,
        })
    }
    pub fn mirror(ks: Vec3) -> Self {
        Self::Thesis(ThesisMaterial {
            kd: Vec3::ZERO,
            ks,
            alpha: f32::INFINITY,
            emission: Vec3::ZERO,
        })
    }
    pub fn emitter(kd: Vec3, emission: Vec3) -> Self {
        Self::Thesis(ThesisMaterial {
            kd,
            ks: Vec3::ZERO,
            alpha: 1.0,
            emission,
        })
    }
    /// A thesis material with every field given.
    pub fn phong(kd: Vec3, ks: Vec3, alpha: f32, emission: Vec3) -> Self {
        Self::Thesis(ThesisMaterial {
            kd,
            ks,
            alpha,
            emission,
        })
    }
    /// Emitted radiance, whatever the model.
    pub fn emission(&self) -> Vec3 {
        match self {
            Self::Thesis(m) => m.emission,
            Self::MetallicRoughness(m) => m.emission,
        }
    }
    /// The emitted radiance, to scale it (the emission checks).
    pub fn emission_mut(&mut self) -> &mut Vec3 {
        match self {
            Self::Thesis(m) => &mut m.emission,
            Self::MetallicRoughness(m) => &mut m.emission,
        }
    }
    pub fn is_emissive(&self) -> bool {
        self.emission().max_element() > 0.0
    }
    /// A thesis material with a Phong or mirror lobe (SPEC_HAS_SPECULAR).
    pub fn is_specular(&self) -> bool {
        matches!(self, Self::Thesis(m) if m.ks.max_element() > 0.0)
    }
    /// The thesis fields, for a thesis material.
    pub fn thesis(&self) -> Option<&ThesisMaterial> {
        match self {
            Self::Thesis(m) => Some(m),
            Self::MetallicRoughness(_) => None,
        }
    }
}

/// An indexed triangle mesh in object space.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Mesh {
    pub name: String,
    pub positions: Vec<Vec3>,
    pub indices: Vec<[u32; 3]>,
    /// What shading reads per vertex besides the position; none for the built-in meshes,
    /// which are shaded with their flat (geometric) normals.
    pub shading: VertexShading,
}

/// Per-vertex shading attributes of a [`Mesh`]. Each list is empty (the mesh has no such
/// attribute) or has one entry per position.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct VertexShading {
    /// Unit shading normals (object space), interpolated across a triangle. A zero vector
    /// marks a vertex whose file normal was unusable (zero or non-finite): triangles that use
    /// it are shaded flat.
    pub normals: Vec<Vec3>,
    /// `TEXCOORD_0` and `TEXCOORD_1`, glTF's convention (origin top left, v down).
    pub uv: [Vec<Vec2>; 2],
    /// Unit tangents (object space, along +u of `TEXCOORD_0`) with the bitangent's sign in w
    /// (glTF's TANGENT, or MikkTSpace's): the frame a normal map's texels are in.
    pub tangents: Vec<Vec4>,
}

impl VertexShading {
    /// Whether the mesh has any per-vertex attribute to interpolate.
    pub fn is_empty(&self) -> bool {
        self.normals.is_empty() && self.uv.iter().all(Vec::is_empty)
    }
}

/// A placement of a mesh in the world with one material.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Instance {
    pub mesh: u32,
    pub material: u32,
    /// Object → world.
    pub transform: Mat4,
}

/// An axis-aligned box in world space.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AaBox {
    pub min: Vec3,
    pub max: Vec3,
    pub material: u32,
}

/// A sphere in world space.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sphere {
    pub center: Vec3,
    pub radius: f32,
    pub material: u32,
}

/// A pinhole camera. The field of view is given as the four half-angles OpenXR reports
/// (`angleLeft` < 0 < `angleRight`, `angleDown` < 0 < `angleUp`, radians), so one type serves
/// desktop (symmetric) and headset (asymmetric, per eye) views.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    pub position: Vec3,
    pub forward: Vec3,
    pub up: Vec3,
    pub angle_left: f32,
    pub angle_right: f32,
    pub angle_up: f32,
    pub angle_down: f32,
}

impl Camera {
    /// A symmetric camera looking from `position` at `target` with vertical field of view
    /// `fov_y_deg`; the horizontal extent follows from the image aspect `width / height`.
    pub fn look_at(position: Vec3, target: Vec3, up: Vec3, fov_y_deg: f32, aspect: f32) -> Self {
        let half_y = (fov_y_deg.to_radians() * 0.5).tan();
        let half_x = (half_y * aspect).atan();
        let half_y = half_y.atan();
        Self {
            position,
            forward: (target - position).normalize(),
            up,
            angle_left: -half_x,
            angle_right: half_x,
            angle_up: half_y,
            angle_down: -half_y,
        }
    }

    /// The same view with the horizontal extent refitted to a new aspect ratio, keeping the
    /// vertical field of view (used when the user renders at another width/height).
    pub fn with_aspect(mut self, aspect: f32) -> Self {
        let up = self.angle_up.tan();
        let down = self.angle_down.tan();
        let half_x = 0.5 * (up - down) * aspect;
        let centre_x = 0.5 * (self.angle_right.tan() + self.angle_left.tan());
        self.angle_left = (centre_x - half_x).atan();
        self.angle_right = (centre_x + half_x).atan();
        self
    }

    /// Orthonormal right, up and forward vectors of the view.
    pub fn basis(&self) -> (Vec3, Vec3, Vec3) {
        let f = self.forward.normalize();
        let r = f.cross(self.up).normalize();
        let u = r.cross(f);
        (r, u, f)
    }
}

/// The background seen by rays that leave the scene: a vertical gradient from `ground`
/// (below the horizon) through `horizon` to `zenith`. Equal colours make a uniform sky.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Environment {
    pub zenith: Vec3,
    pub horizon: Vec3,
    pub ground: Vec3,
}

impl Environment {
    pub fn uniform(radiance: Vec3) -> Self {
        Self {
            zenith: radiance,
            horizon: radiance,
            ground: radiance,
        }
    }
    pub fn sky() -> Self {
        Self {
            zenith: Vec3::new(0.25, 0.45, 0.85),
            horizon: Vec3::new(0.85, 0.9, 1.0),
            ground: Vec3::new(0.3, 0.28, 0.25),
        }
    }
    pub fn black() -> Self {
        Self::uniform(Vec3::ZERO)
    }
}

/// A whole scene, ready to be turned into BVHs and GPU buffers.
#[derive(Clone, Debug)]
pub struct Scene {
    pub name: String,
    pub meshes: Vec<Mesh>,
    pub instances: Vec<Instance>,
    pub boxes: Vec<AaBox>,
    pub spheres: Vec<Sphere>,
    pub materials: Vec<Material>,
    /// The images glTF materials sample ([`TextureRef::texture`] indexes it).
    pub textures: Vec<Texture>,
    pub camera: Camera,
    pub environment: Environment,
    /// glTF's punctual lights (`KHR_lights_punctual`), in world space.
    pub lights: Vec<super::PunctualLight>,
    /// An HDR environment that replaces `environment` (the gradient sky) where given.
    pub environment_map: Option<super::EnvironmentLight>,
    /// How next-event estimation weighs the lights (by power, or uniformly for comparison).
    pub light_selection: super::LightSelection,
}

impl Scene {
    pub fn triangle_count(&self) -> usize {
        self.instances
            .iter()
            .map(|i| self.meshes[i.mesh as usize].indices.len())
            .sum()
    }
}
