//! glTF textures as the path tracer reads them: a quad under a uniform sky of radiance 1 shows,
//! at every pixel, its material's directional albedo there (every reflected ray escapes), which
//! the CPU reference computes from the texel's value. So a base colour texel must be decoded
//! from sRGB, a metallic-roughness texel read as stored, a factor multiply its texel, and
//! KHR_texture_transform move the lookup as the extension says.

mod common;

use fovea::check::gltf_brdf::GltfBrdf;
use fovea::render::Integrator;
use fovea::scene::gltf_load::load_gltf;
use fovea::scene::{
    Camera, Environment, Instance, Material, MaterialTextures, Mesh, MetallicRoughness, Scene,
    TexelEncoding, Texture, TextureRef, TextureSampler, VertexShading,
};
use glam::{DVec3, Mat4, Vec2, Vec3};

const SIZE: usize = 32;

/// A 2 × 2 quad in the z = 0 plane facing +z, its texture's top-left texel at the image's
/// top left (glTF's uv (0, 0) is the image's first texel).
fn textured_quad() -> Mesh {
    Mesh {
        name: "quad".into(),
        positions: vec![
            Vec3::new(-1.0, -1.0, 0.0),
            Vec3::new(1.0, -1.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(-1.0, 1.0, 0.0),
        ],
        indices: vec![[0, 1, 2], [0, 2, 3]],
        shading: VertexShading {
            normals: vec![],
            uv: [
                vec![
                    Vec2::new(0.0, 1.0),
                    Vec2::new(1.0, 1.0),
                    Vec2::new(1.0, 0.0),
                    Vec2::new(0.0, 0.0),
                ],
                vec![],
            ],
        },
    }
}

/// 2 × 2 texels, read exactly: nearest filtering, no mipmaps.
fn texture(texels: [[u8; 4]; 4], encoding: TexelEncoding) -> Texture {
    Texture {
        name: "2x2".into(),
        width: 2,
        height: 2,
        rgba8: texels.concat(),
        encoding,
        sampler: TextureSampler {
            mag_linear: false,
            min_linear: false,
            mipmaps: false,
            ..TextureSampler::DEFAULT
        },
    }
}

fn slot() -> Option<TextureRef> {
    Some(TextureRef {
        texture: 0,
        texcoord: 0,
        transform: TextureRef::IDENTITY,
    })
}

/// The quad filling the view from straight above, under a white sky.
fn scene(material: MetallicRoughness, texture: Texture) -> Scene {
    Scene {
        name: "textured-quad".into(),
        meshes: vec![textured_quad()],
        instances: vec![Instance {
            mesh: 0,
            material: 0,
            transform: Mat4::IDENTITY,
        }],
        boxes: vec![],
        spheres: vec![],
        materials: vec![Material::MetallicRoughness(material)],
        textures: vec![texture],
        camera: Camera::look_at(Vec3::new(0.0, 0.0, 4.0), Vec3::ZERO, Vec3::Y, 26.0, 1.0),
        environment: Environment::uniform(Vec3::ONE),
    }
}

/// Per texel (quadrant of the image, a pixel's margin left out): the mean RGB, its standard
/// error, and the mean |cos| of the view angle over those pixels.
fn quadrants(scene: &Scene) -> Vec<(DVec3, DVec3, f64)> {
    let ctx = common::context();
    let frame = common::render(
        &ctx,
        scene,
        &common::settings(SIZE as u32, SIZE as u32, 256, 3, Integrator::Pt),
    );
    let (r, u, f) = scene.camera.basis();
    let tan_y = scene.camera.angle_up.tan();
    let half = SIZE / 2;
    let mut out = Vec::new();
    for (qy, qx) in [(0, 0), (0, 1), (1, 0), (1, 1)] {
        let mut values = Vec::new();
        let mut cos = 0.0;
        for y in qy * half + 1..(qy + 1) * half - 1 {
            for x in qx * half + 1..(qx + 1) * half - 1 {
                let i = 3 * (y * SIZE + x);
                values.push(DVec3::new(
                    frame.rgb[i] as f64,
                    frame.rgb[i + 1] as f64,
                    frame.rgb[i + 2] as f64,
                ));
                let tx = ((x as f32 + 0.5) / SIZE as f32 * 2.0 - 1.0) * tan_y;
                let ty = (1.0 - (y as f32 + 0.5) / SIZE as f32 * 2.0) * tan_y;
                cos += (f + tx * r + ty * u).normalize().z.abs() as f64;
            }
        }
        let n = values.len() as f64;
        let mean = values.iter().copied().sum::<DVec3>() / n;
        let var = values
            .iter()
            .map(|v| (*v - mean) * (*v - mean))
            .sum::<DVec3>()
            / (n - 1.0);
        out.push((mean, (var / n).powf(0.5), cos / n));
    }
    out
}

fn srgb_decode(byte: u8) -> f64 {
    let x = byte as f64 / 255.0;
    if x <= 0.04045 {
        x / 12.92
    } else {
        ((x + 0.055) / 1.055).powf(2.4)
    }
}

fn assert_albedo(what: &str, measured: (DVec3, DVec3, f64), brdf: GltfBrdf) {
    let (mean, std_error, cos) = measured;
    let expected = brdf.albedo(cos, 300);
    eprintln!("{what}: {mean:.4} ± {std_error:.4}, expected {expected:.4}");
    for c in 0..3 {
        let tolerance = 4.0 * std_error[c] + 0.005 * expected[c] + 1e-3;
        assert!(
            (mean[c] - expected[c]).abs() < tolerance,
            "{what} channel {c}: {} for {} ({brdf:?})",
            mean[c],
            expected[c]
        );
    }
}

#[test]
fn base_colour_texels_are_srgb_decoded_and_multiply_the_factor() {
    let texels = [
        [255, 128, 64, 255],
        [32, 200, 10, 255],
        [190, 190, 190, 255],
        [0, 90, 255, 255],
    ];
    let factor = Vec3::new(1.0, 0.8, 0.6);
    let material = MetallicRoughness {
        textures: MaterialTextures {
            base_color: slot(),
            ..MaterialTextures::NONE
        },
        ..MetallicRoughness::factors(factor, 0.0, 1.0, Vec3::ZERO)
    };
    let measured = quadrants(&scene(material, texture(texels, TexelEncoding::Srgb)));
    for (texel, m) in texels.iter().zip(measured) {
        let base = DVec3::new(
            srgb_decode(texel[0]),
            srgb_decode(texel[1]),
            srgb_decode(texel[2]),
        ) * factor.as_dvec3();
        let brdf = GltfBrdf {
            base_color: base,
            metallic: 0.0,
            roughness: 1.0,
        };
        assert_albedo(&format!("base colour texel {texel:?}"), m, brdf);
    }
}

#[test]
fn metallic_roughness_texels_are_read_as_stored() {
    // Blue is metalness, green roughness (glTF 2.0, 3.9.2), both linear: byte 128 is 0.502.
    let texels = [
        [0, 255, 0, 255],
        [0, 128, 255, 255],
        [0, 200, 128, 255],
        [0, 255, 255, 255],
    ];
    let base = Vec3::new(0.9, 0.6, 0.3);
    let material = MetallicRoughness {
        textures: MaterialTextures {
            metallic_roughness: slot(),
            ..MaterialTextures::NONE
        },
        ..MetallicRoughness::factors(base, 1.0, 1.0, Vec3::ZERO)
    };
    let measured = quadrants(&scene(material, texture(texels, TexelEncoding::Linear)));
    for (texel, m) in texels.iter().zip(measured) {
        let brdf = GltfBrdf {
            base_color: base.as_dvec3(),
            metallic: texel[2] as f64 / 255.0,
            roughness: texel[1] as f64 / 255.0,
        };
        assert_albedo(&format!("metallic-roughness texel {texel:?}"), m, brdf);
    }
}

#[test]
fn box_textured_reads_its_image() {
    // Khronos' BoxTextured (Debian's assimp-testmodels): one texture, the Cesium logo, used as
    // base colour; its texels are not all one colour, so neither is the box.
    let path = "/usr/share/assimp/models/glTF2/BoxTextured-glTF/BoxTextured.gltf";
    let scene = load_gltf(path.as_ref(), 1.0).expect("tools/setup.sh installs assimp-testmodels");
    assert_eq!(scene.textures.len(), 1);
    let t = &scene.textures[0];
    assert_eq!(
        (t.width, t.height, t.encoding),
        (211, 211, TexelEncoding::Srgb)
    );
    let Material::MetallicRoughness(m) = scene.materials[0] else {
        panic!("a glTF material: {:?}", scene.materials[0]);
    };
    assert_eq!(m.textures.base_color.map(|r| r.texture), Some(0));
    let ctx = common::context();
    let frame = common::render(
        &ctx,
        &scene,
        &common::settings(48, 48, 16, 1, Integrator::Pt),
    );
    // The logo's blue and green both show on the box's faces.
    let pixels: Vec<&[f32]> = frame.rgb.chunks_exact(3).collect();
    let blue = pixels
        .iter()
        .filter(|p| p[2] > 1.5 * p[0] && p[2] > p[1])
        .count();
    let green = pixels
        .iter()
        .filter(|p| p[1] > 1.5 * p[0] && p[1] > p[2])
        .count();
    assert!(blue > 20 && green > 20, "blue {blue}, green {green} pixels");
}
