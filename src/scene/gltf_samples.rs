//! fovea's own glTF scenes for tests and users, built here and written by the glb writer to
//! `assets/gltf/` (`cargo run --example write_gltf_samples`): a grid of spheres over metallic ×
//! roughness, a normal-mapped quad, an alpha-cut card casting a shadow, and a panel lit by
//! `KHR_materials_emissive_strength`, a textured room, and a scene lit by `KHR_lights_punctual`.
//! Each has a ground, a light made of emissive geometry (glTF has no area lights) and a camera. tests/gltf_samples.rs checks the files are what this
//! code writes.

use std::f32::consts::{PI, TAU};

use glam::{Mat4, Vec2, Vec3};

use super::shapes::{cube, quad, uv_sphere};
use super::{
    AlphaMode, Camera, Coverage, Environment, Instance, LightKind, Material, MaterialTextures,
    Mesh, MetallicRoughness, PunctualLight, Scene, TexelEncoding, Texture, TextureRef,
    TextureSampler,
};

/// Every sample scene, by the file name it is written under (without `.glb`).
pub fn gltf_samples() -> Vec<Scene> {
    vec![
        sphere_grid(),
        normal_mapped_quad(),
        alpha_card(),
        emissive_panel(),
        textured_room(),
        punctual_lights(),
    ]
}

/// Three spheres and a cube on a ground lit by `KHR_lights_punctual` alone: a warm point
/// light, a spot with a soft edge on the cube and a low sun, plus a small emissive panel (a
/// scene may mix them). The lights' intensities are candela and lux, as fovea reads them.
pub fn punctual_lights() -> Scene {
    let mut b = SampleBuilder::new("punctual-lights");
    b.ground(8.0, Vec3::splat(0.6));
    let sphere = b.mesh(uv_sphere(32, 16));
    for (i, (base, metallic, roughness)) in [
        (Vec3::new(0.8, 0.2, 0.2), 0.0, 0.5),
        (Vec3::new(0.9, 0.9, 0.9), 1.0, 0.3),
        (Vec3::new(0.2, 0.5, 0.8), 0.0, 0.9),
    ]
    .into_iter()
    .enumerate()
    {
        let m = b.material(MetallicRoughness::factors(
            base,
            metallic,
            roughness,
            Vec3::ZERO,
        ));
        let at = Vec3::new(i as f32 * 1.2 - 1.2, 0.5, 0.0);
        b.place(
            sphere,
            m,
            Mat4::from_translation(at) * Mat4::from_scale(Vec3::splat(0.5)),
        );
    }
    let cube = b.mesh(cube());
    let m = b.material(MetallicRoughness::factors(
        Vec3::splat(0.8),
        0.0,
        0.7,
        Vec3::ZERO,
    ));
    b.place(
        cube,
        m,
        Mat4::from_translation(Vec3::new(0.6, 0.3, 1.4)) * Mat4::from_scale(Vec3::splat(0.3)),
    );
    b.light(Vec3::new(-2.5, 2.0, -1.5), 0.5, 8.0);
    let lights = &mut b.scene.lights;
    lights.push(PunctualLight {
        kind: LightKind::Point,
        intensity: Vec3::new(6.0, 4.5, 3.0),
        position: Vec3::new(-1.5, 2.2, 1.5),
        direction: Vec3::NEG_Z,
        range: None,
    });
    lights.push(PunctualLight {
        kind: LightKind::Spot {
            inner_cone_angle: 0.2,
            outer_cone_angle: 0.45,
        },
        intensity: Vec3::splat(12.0),
        position: Vec3::new(1.5, 3.0, 2.5),
        direction: (Vec3::new(0.6, 0.3, 1.4) - Vec3::new(1.5, 3.0, 2.5)).normalize(),
        range: Some(20.0),
    });
    lights.push(PunctualLight {
        kind: LightKind::Directional,
        intensity: Vec3::new(1.0, 0.8, 0.6),
        position: Vec3::ZERO,
        direction: Vec3::new(1.0, -0.5, -0.6).normalize(),
        range: None,
    });
    b.finish(Camera::look_at(
        Vec3::new(0.0, 2.5, 5.5),
        Vec3::new(0.0, 0.4, 0.3),
        Vec3::Y,
        45.0,
        1.0,
    ))
}

/// 5 × 5 spheres: metallic 0 → 1 from front to back, roughness 0.05 → 1 from left to right,
/// under a large panel light.
pub fn sphere_grid() -> Scene {
    let mut b = SampleBuilder::new("sphere-grid");
    b.ground(8.0, Vec3::splat(0.5));
    b.light(Vec3::new(0.0, 6.0, 2.0), 4.0, 6.0);
    let sphere = b.mesh(uv_sphere(32, 16));
    for (row, metallic) in [0.0, 0.25, 0.5, 0.75, 1.0].into_iter().enumerate() {
        for (col, roughness) in [0.05, 0.25, 0.5, 0.75, 1.0].into_iter().enumerate() {
            let base = Vec3::new(0.9, 0.6, 0.3);
            let material = b.material(MetallicRoughness::factors(
                base,
                metallic,
                roughness,
                Vec3::ZERO,
            ));
            let at = Vec3::new(col as f32 - 2.0, 0.4, 2.0 - row as f32);
            b.place(
                sphere,
                material,
                Mat4::from_translation(at) * Mat4::from_scale(Vec3::splat(0.4)),
            );
        }
    }
    b.finish(Camera::look_at(
        Vec3::new(0.0, 4.5, 6.5),
        Vec3::new(0.0, 0.0, 0.3),
        Vec3::Y,
        45.0,
        1.0,
    ))
}

/// A 2 × 2 quad whose normal map carries ridges across u (a height of sin(8πu)), under a
/// light that grazes it from the side so the ridges show.
pub fn normal_mapped_quad() -> Scene {
    let mut b = SampleBuilder::new("normal-mapped-quad");
    b.light(Vec3::new(-3.0, 2.0, 0.0), 1.0, 8.0);
    let texture = b.texture(ridges_normal_map(64), TexelEncoding::Linear);
    let material = b.material(MetallicRoughness {
        textures: MaterialTextures {
            normal: Some(slot(texture)),
            ..MaterialTextures::NONE
        },
        ..MetallicRoughness::factors(Vec3::splat(0.8), 0.0, 0.5, Vec3::ZERO)
    });
    let quad = b.mesh(quad());
    b.place(quad, material, Mat4::from_rotation_x(-PI / 2.0));
    b.finish(Camera::look_at(
        Vec3::new(0.0, 3.0, 1.5),
        Vec3::ZERO,
        Vec3::Y,
        50.0,
        1.0,
    ))
}

/// A card cut out by a checkerboard alpha texture (MASK at 0.5), tilted above the ground under
/// a small light: its shadow is the checkerboard's.
pub fn alpha_card() -> Scene {
    let mut b = SampleBuilder::new("alpha-card");
    b.ground(6.0, Vec3::splat(0.7));
    b.light(Vec3::new(0.0, 5.0, 0.0), 0.5, 60.0);
    let texture = b.texture(checker_alpha(8), TexelEncoding::Srgb);
    let material = b.material(MetallicRoughness {
        textures: MaterialTextures {
            base_color: Some(slot(texture)),
            ..MaterialTextures::NONE
        },
        coverage: Coverage {
            alpha: 1.0,
            mode: AlphaMode::Mask { cutoff: 0.5 },
            double_sided: true,
        },
        ..MetallicRoughness::factors(Vec3::new(0.9, 0.2, 0.2), 0.0, 0.6, Vec3::ZERO)
    });
    let quad = b.mesh(quad());
    let tilt =
        Mat4::from_translation(Vec3::new(0.0, 1.5, 0.0)) * Mat4::from_rotation_x(-PI / 2.0 + 0.3);
    b.place(quad, material, tilt);
    b.finish(Camera::look_at(
        Vec3::new(0.0, 4.0, 5.0),
        Vec3::ZERO,
        Vec3::Y,
        45.0,
        1.0,
    ))
}

/// A panel whose emission is past 1 by KHR_materials_emissive_strength (strength 25), the
/// only light of a ground and a sphere.
pub fn emissive_panel() -> Scene {
    let mut b = SampleBuilder::new("emissive-panel");
    b.ground(6.0, Vec3::splat(0.6));
    let panel = b.material(MetallicRoughness::factors(
        Vec3::ZERO,
        0.0,
        1.0,
        Vec3::new(25.0, 20.0, 15.0),
    ));
    let quad = b.mesh(quad());
    let standing = Mat4::from_translation(Vec3::new(0.0, 1.0, -1.5))
        * Mat4::from_scale(Vec3::new(1.2, 0.8, 1.0));
    b.place(quad, panel, standing);
    let sphere = b.mesh(uv_sphere(32, 16));
    let white = b.material(MetallicRoughness::factors(
        Vec3::splat(0.8),
        0.0,
        0.4,
        Vec3::ZERO,
    ));
    b.place(
        sphere,
        white,
        Mat4::from_translation(Vec3::new(0.0, 0.5, 0.0)) * Mat4::from_scale(Vec3::splat(0.5)),
    );
    b.finish(Camera::look_at(
        Vec3::new(0.0, 2.0, 4.0),
        Vec3::new(0.0, 0.5, 0.0),
        Vec3::Y,
        45.0,
        1.0,
    ))
}

/// A closed room (no ray escapes: the environment plays no part) with base-colour textures on
/// the floor, the back wall and a box, rough dielectrics all (roughness 1), lit by a ceiling
/// panel. Its textures are read texel by texel (nearest, no mipmaps), so a renderer without
/// ray cones sees the same colours: tools/mitsuba-gltf.py compares it with Mitsuba 3.
pub fn textured_room() -> Scene {
    let mut b = SampleBuilder::new("textured-room");
    let quad = b.mesh(quad());
    let rough = |colour: Vec3| MetallicRoughness::factors(colour, 0.0, 1.0, Vec3::ZERO);
    let textured = |texture: u32| MetallicRoughness {
        textures: MaterialTextures {
            base_color: Some(slot(texture)),
            ..MaterialTextures::NONE
        },
        ..rough(Vec3::ONE)
    };
    let floor_texture = b.texture(colour_cells(8, 7), TexelEncoding::Srgb);
    let wall_texture = b.texture(colour_cells(4, 3), TexelEncoding::Srgb);
    let floor = b.material(textured(floor_texture));
    let back = b.material(textured(wall_texture));
    let white = b.material(rough(Vec3::splat(0.75)));
    let red = b.material(rough(Vec3::new(0.7, 0.15, 0.1)));
    // The room spans x, z in [-2, 2] and y in [0, 3]; every wall faces inward.
    let wall = |at: Vec3, rotation: Mat4, half: Vec2| {
        Mat4::from_translation(at) * rotation * Mat4::from_scale(half.extend(1.0))
    };
    let rx = Mat4::from_rotation_x;
    let ry = Mat4::from_rotation_y;
    b.place(
        quad,
        floor,
        wall(Vec3::ZERO, rx(-PI / 2.0), Vec2::splat(2.0)),
    );
    b.place(
        quad,
        white,
        wall(Vec3::Y * 3.0, rx(PI / 2.0), Vec2::splat(2.0)),
    );
    b.place(
        quad,
        back,
        wall(
            Vec3::new(0.0, 1.5, -2.0),
            Mat4::IDENTITY,
            Vec2::new(2.0, 1.5),
        ),
    );
    b.place(
        quad,
        white,
        wall(Vec3::new(0.0, 1.5, 2.0), ry(PI), Vec2::new(2.0, 1.5)),
    );
    b.place(
        quad,
        red,
        wall(Vec3::new(-2.0, 1.5, 0.0), ry(PI / 2.0), Vec2::new(2.0, 1.5)),
    );
    b.place(
        quad,
        white,
        wall(Vec3::new(2.0, 1.5, 0.0), ry(-PI / 2.0), Vec2::new(2.0, 1.5)),
    );
    // A textured box standing on the floor, turned a little.
    let cube = b.mesh(cube());
    let box_texture = b.texture(colour_cells(2, 5), TexelEncoding::Srgb);
    let boxed = b.material(textured(box_texture));
    let placed = Mat4::from_translation(Vec3::new(0.4, 0.5, -0.6))
        * ry(0.5)
        * Mat4::from_scale(Vec3::splat(0.5));
    b.place(cube, boxed, placed);
    b.light(Vec3::new(0.0, 2.99, 0.0), 1.0, 12.0);
    b.finish(Camera::look_at(
        Vec3::new(0.0, 1.5, 1.9),
        Vec3::new(0.0, 1.0, -2.0),
        Vec3::Y,
        60.0,
        1.0,
    ))
}

/// Collects a sample's meshes, materials, textures and instances.
struct SampleBuilder {
    scene: Scene,
}

impl SampleBuilder {
    fn new(name: &str) -> Self {
        Self {
            scene: Scene {
                name: name.into(),
                meshes: Vec::new(),
                instances: Vec::new(),
                boxes: Vec::new(),
                spheres: Vec::new(),
                materials: Vec::new(),
                textures: Vec::new(),
                camera: Camera::look_at(Vec3::Z, Vec3::ZERO, Vec3::Y, 45.0, 1.0),
                environment: Environment::black(),
                lights: Vec::new(),
                environment_map: None,
                light_selection: Default::default(),
            },
        }
    }

    fn mesh(&mut self, mesh: Mesh) -> u32 {
        self.scene.meshes.push(mesh);
        self.scene.meshes.len() as u32 - 1
    }

    fn material(&mut self, m: MetallicRoughness) -> u32 {
        self.scene.materials.push(Material::MetallicRoughness(m));
        self.scene.materials.len() as u32 - 1
    }

    fn texture(&mut self, t: Texture, encoding: TexelEncoding) -> u32 {
        self.scene.textures.push(Texture { encoding, ..t });
        self.scene.textures.len() as u32 - 1
    }

    fn place(&mut self, mesh: u32, material: u32, transform: Mat4) {
        self.scene.instances.push(Instance {
            mesh,
            material,
            transform,
        });
    }

    /// A square ground of side `size` at y = 0, facing up.
    fn ground(&mut self, size: f32, colour: Vec3) {
        let quad = self.mesh(quad());
        let m = self.material(MetallicRoughness::factors(colour, 0.0, 0.8, Vec3::ZERO));
        let flat = Mat4::from_rotation_x(-PI / 2.0) * Mat4::from_scale(Vec3::splat(size / 2.0));
        self.place(quad, m, flat);
    }

    /// A square emissive panel of side `size` at `at`, facing down, of radiance `radiance`.
    fn light(&mut self, at: Vec3, size: f32, radiance: f32) {
        let quad = self.mesh(quad());
        let m = self.material(MetallicRoughness::factors(
            Vec3::ZERO,
            0.0,
            1.0,
            Vec3::splat(radiance),
        ));
        let down = Mat4::from_translation(at)
            * Mat4::from_rotation_x(PI / 2.0)
            * Mat4::from_scale(Vec3::splat(size / 2.0));
        self.place(quad, m, down);
    }

    fn finish(self, camera: Camera) -> Scene {
        Scene {
            camera,
            ..self.scene
        }
    }
}

fn slot(texture: u32) -> TextureRef {
    TextureRef {
        texture,
        texcoord: 0,
        transform: TextureRef::IDENTITY,
    }
}

/// `cells` × `cells` texels of distinct, saturated colours (a hue per texel, `seed` shifting
/// them), read exactly (nearest, no mipmaps).
fn colour_cells(cells: u32, seed: u32) -> Texture {
    let rgba8 = (0..cells * cells)
        .flat_map(|i| {
            let k = (i * 7 + seed * 13) % 24;
            let hue = k as f32 / 24.0 * TAU;
            let channel = |shift: f32| (0.55 + 0.4 * (hue + shift).cos()) * 255.0;
            [
                channel(0.0) as u8,
                channel(2.1) as u8,
                channel(4.2) as u8,
                255,
            ]
        })
        .collect();
    Texture {
        name: format!("cells {cells}x{cells}"),
        width: cells,
        height: cells,
        rgba8,
        encoding: TexelEncoding::Srgb,
        sampler: TextureSampler {
            mag_linear: false,
            min_linear: false,
            mipmaps: false,
            ..TextureSampler::DEFAULT
        },
    }
}

/// Tangent-space normals of ridges across u: height sin(8πu) / 16, so the normal leans ±x.
fn ridges_normal_map(size: u32) -> Texture {
    let rgba8 = (0..size * size)
        .flat_map(|i| {
            let u = ((i % size) as f32 + 0.5) / size as f32;
            let slope = (8.0 * PI / 16.0) * (8.0 * PI * u).cos();
            let n = Vec3::new(-slope, 0.0, 1.0).normalize();
            let byte = |x: f32| ((x * 0.5 + 0.5) * 255.0).round() as u8;
            [byte(n.x), byte(n.y), byte(n.z), 255]
        })
        .collect();
    Texture {
        name: "ridges".into(),
        width: size,
        height: size,
        rgba8,
        encoding: TexelEncoding::Linear,
        sampler: TextureSampler::DEFAULT,
    }
}

/// `cells` × `cells` texels of white, alpha a checkerboard, read exactly (nearest, no mips).
pub fn checker_alpha(cells: u32) -> Texture {
    let rgba8 = (0..cells * cells)
        .flat_map(|i| {
            [
                255,
                255,
                255,
                if (i % cells + i / cells).is_multiple_of(2) {
                    255
                } else {
                    0
                },
            ]
        })
        .collect();
    Texture {
        name: "checker".into(),
        width: cells,
        height: cells,
        rgba8,
        encoding: TexelEncoding::Srgb,
        sampler: TextureSampler {
            mag_linear: false,
            min_linear: false,
            mipmaps: false,
            ..TextureSampler::DEFAULT
        },
    }
}
