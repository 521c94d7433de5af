//! What a scene needs from the shaders. Each flag becomes a specialization constant, so the
//! driver compiles away the intersection and shading paths a scene never uses.

use super::{Coverage, Material, Scene};

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SceneFeatures {
    pub triangles: bool,
    pub boxes: bool,
    pub spheres: bool,
    /// Any material with a Phong or mirror lobe (k_s > 0).
    pub specular: bool,
    /// Any emissive surface (next-event estimation has something to sample).
    pub emitters: bool,
    /// Any instanced mesh with shading normals or texture coordinates.
    pub shading: bool,
    /// Any glTF metallic-roughness material (the built-in scenes have none).
    pub metallic_roughness: bool,
    /// Any material that samples a texture.
    pub textures: bool,
    /// Any mesh instance whose alpha cuts holes in it (glTF's MASK or BLEND).
    pub cutouts: bool,
    /// Any mesh instance that is single-sided (glTF's default).
    pub single_sided: bool,
    /// Any punctual light that emits (found only by next-event estimation).
    pub punctual_lights: bool,
    /// An HDR environment map in place of the gradient sky (a light for next-event estimation).
    pub env_map: bool,
}

impl SceneFeatures {
    pub fn of(scene: &Scene) -> Self {
        let used = |m: u32| scene.materials.get(m as usize);
        let materials = scene
            .instances
            .iter()
            .map(|i| i.material)
            .chain(scene.boxes.iter().map(|b| b.material))
            .chain(scene.spheres.iter().map(|s| s.material))
            .filter_map(used);
        let (mut specular, mut emitters, mut metallic_roughness) = (false, false, false);
        let mut textures = false;
        for m in materials {
            specular |= m.is_specular();
            emitters |= m.is_emissive();
            if let Material::MetallicRoughness(m) = m {
                metallic_roughness = true;
                textures |= m.textures.iter().next().is_some();
            }
        }
        // Coverage is applied to triangles only: boxes and spheres are closed and opaque.
        let coverages: Vec<Coverage> = (scene.instances.iter())
            .filter_map(|i| used(i.material))
            .filter_map(|m| match m {
                Material::MetallicRoughness(m) => Some(m.coverage),
                Material::Thesis(_) => None,
            })
            .collect();
        let shading = (scene.instances.iter())
            .filter_map(|i| scene.meshes.get(i.mesh as usize))
            .any(|m| !m.shading.is_empty());
        Self {
            shading,
            triangles: scene.triangle_count() > 0,
            boxes: !scene.boxes.is_empty(),
            spheres: !scene.spheres.is_empty(),
            specular,
            emitters: emitters
                || scene.environment_map.is_some()
                || scene.lights.iter().any(|l| l.intensity.max_element() > 0.0),
            metallic_roughness,
            textures,
            cutouts: coverages.iter().any(|c| c.cuts_out()),
            single_sided: coverages.iter().any(|c| !c.double_sided),
            punctual_lights: scene.lights.iter().any(|l| l.intensity.max_element() > 0.0),
            env_map: scene.environment_map.is_some(),
        }
    }

    /// A short list for `fovea scenes`, e.g. "triangles boxes specular".
    pub fn describe(&self) -> String {
        let names = [
            (self.triangles, "triangles"),
            (self.boxes, "boxes"),
            (self.spheres, "spheres"),
            (self.specular, "specular"),
            (self.emitters, "emitters"),
            (self.shading, "smooth/uv"),
            (self.metallic_roughness, "metallic-roughness"),
            (self.textures, "textures"),
            (self.cutouts, "alpha"),
            (self.single_sided, "single-sided"),
            (self.punctual_lights, "punctual-lights"),
            (self.env_map, "environment-map"),
        ];
        let on: Vec<_> = names.iter().filter(|(f, _)| *f).map(|(_, n)| *n).collect();
        if on.is_empty() {
            "background only".into()
        } else {
            on.join(" ")
        }
    }
}
