//! Shading normals and texture coordinates of meshes (glTF's NORMAL, TEXCOORD_0/1): read by
//! the loader, written back by the glb writer, interpolated by the shaders, and kept from
//! leaking light through the geometry or blacking out grazing hits.

mod common;

use fovea::check::closed_meshes::icosphere;
use fovea::check::scale::quad;
use fovea::render::{Frame, Integrator};
use fovea::scene::glb_write::glb_bytes;
use fovea::scene::gltf_load::load_gltf_bytes;
use fovea::scene::{Camera, Environment, Instance, Material, Mesh, Scene, Sphere};
use glam::{Mat4, Vec2, Vec3};

const SIZE: u32 = 40;

/// One diffuse object seen from +Z under `environment`, filling the middle of the frame.
fn one_object(name: &str, mesh: Option<Mesh>, environment: Environment) -> Scene {
    let camera = Camera::look_at(Vec3::new(0.0, 0.0, 4.0), Vec3::ZERO, Vec3::Y, 36.0, 1.0);
    let mut scene = Scene {
        name: name.into(),
        meshes: vec![],
        instances: vec![],
        boxes: vec![],
        spheres: vec![],
        materials: vec![Material::diffuse(Vec3::splat(0.7))],
        textures: Vec::new(),
        camera,
        environment,
        lights: Vec::new(),
        environment_map: None,
        light_selection: Default::default(),
    };
    match mesh {
        Some(mesh) => {
            scene.meshes.push(mesh);
            scene.instances.push(Instance {
                mesh: 0,
                material: 0,
                transform: Mat4::IDENTITY,
            });
        }
        None => scene.spheres.push(Sphere {
            center: Vec3::ZERO,
            radius: 1.0,
            material: 0,
        }),
    }
    scene
}

/// A unit icosphere whose shading normals are the true sphere's (its positions).
fn smooth_icosphere(subdivisions: u32) -> Mesh {
    let mut mesh = icosphere(subdivisions);
    mesh.shading.normals = mesh.positions.iter().map(|p| p.normalize()).collect();
    mesh
}

fn render(scene: &Scene, spp: u32) -> Frame {
    let ctx = common::context();
    common::render(
        &ctx,
        scene,
        &common::settings(SIZE, SIZE, spp, 7, Integrator::Pt),
    )
}

/// Pixels within `radius` pixels of the image centre.
fn disk(radius: f32) -> Vec<usize> {
    let c = (SIZE as f32 - 1.0) / 2.0;
    (0..(SIZE * SIZE) as usize)
        .filter(|&i| {
            let (x, y) = ((i as u32 % SIZE) as f32, (i as u32 / SIZE) as f32);
            Vec2::new(x - c, y - c).length() <= radius
        })
        .collect()
}

fn mean_abs_difference(a: &Frame, b: &Frame, pixels: &[usize]) -> f64 {
    let sum: f64 = pixels
        .iter()
        .flat_map(|&i| (0..3).map(move |c| 3 * i + c))
        .map(|k| (a.rgb[k] - b.rgb[k]).abs() as f64)
        .sum();
    sum / (3 * pixels.len()) as f64
}

#[test]
fn smooth_normals_shade_a_coarse_sphere_like_the_true_sphere() {
    // Under the sky's gradient a diffuse point's radiance follows its normal. An 80-triangle
    // icosphere shaded flat shows its facets; with the sphere's normals it must shade like
    // the analytic sphere. All three are rendered at the same seed, so most of the noise is
    // common to them and the difference left is the shading's.
    let sky = Environment::sky();
    let truth = render(&one_object("analytic", None, sky), 64);
    let flat = render(&one_object("flat", Some(icosphere(1)), sky), 64);
    let smooth = render(&one_object("smooth", Some(smooth_icosphere(1)), sky), 64);
    // The sphere spans about 16 pixels of radius here; inside 11 every ray hits all three.
    let inside = disk(11.0);
    let flat_error = mean_abs_difference(&flat, &truth, &inside);
    let smooth_error = mean_abs_difference(&smooth, &truth, &inside);
    assert!(
        smooth_error < 0.5 * flat_error,
        "smooth {smooth_error:.5} vs flat {flat_error:.5}: interpolated normals did not remove \
         the facets"
    );
}

#[test]
fn grazing_hits_on_smooth_coarse_meshes_are_not_black() {
    // A mirror icosahedron (20 triangles) with the sphere's normals under a uniform sky: near
    // its outline the interpolated normal leans far from the face's, and the mirror direction
    // about it points into the face. Bent back (valid_shading_normal) every reflection leaves
    // the convex object and sees the sky, so every pixel on it shows k_s·L; unbent, the
    // grazing ones would be black.
    let (ks, radiance) = (0.9, 1.0);
    let mut scene = one_object(
        "icosahedron",
        Some(smooth_icosphere(0)),
        Environment::uniform(Vec3::splat(radiance)),
    );
    scene.materials[0] = Material::mirror(Vec3::splat(ks));
    let frame = render(&scene, 4);
    // Every pixel shows the sky: directly (L) or in the mirror (k_s·L), outline included.
    let (darkest, at) = (frame.rgb.iter().skip(1).step_by(3).enumerate())
        .map(|(i, &g)| (g, i))
        .fold((f32::INFINITY, 0), |a, b| if b.0 < a.0 { b } else { a });
    assert!(
        darkest > 0.99 * ks * radiance,
        "pixel ({}, {}) has radiance {darkest}, not k_s·L = {} or L",
        at as u32 % SIZE,
        at as u32 / SIZE,
        ks * radiance
    );
}

#[test]
fn normals_facing_away_from_their_face_shade_it_flat() {
    // Shading normals opposite to the geometric one are unusable: the face is shaded flat,
    // neither black nor lit through from behind.
    let sky = Environment::sky();
    let mut reversed = quad();
    reversed.shading.normals = vec![Vec3::NEG_Y; reversed.positions.len()];
    let lying = |mesh: Mesh| {
        let mut scene = one_object("quad", Some(mesh), sky);
        scene.camera = Camera::look_at(Vec3::new(0.0, 2.0, 0.5), Vec3::ZERO, Vec3::Y, 30.0, 1.0);
        scene.instances[0].transform = Mat4::from_scale(Vec3::new(50.0, 1.0, 50.0));
        scene
    };
    let flat = render(&lying(quad()), 16);
    let odd = render(&lying(reversed), 16);
    let all: Vec<usize> = (0..(SIZE * SIZE) as usize).collect();
    let difference = mean_abs_difference(&flat, &odd, &all);
    assert!(
        difference < 1e-4 * flat.mean()[1],
        "mean difference {difference} from the flat quad"
    );
}

#[test]
fn normals_and_texture_coordinates_survive_the_glb_round_trip() {
    let mut mesh = smooth_icosphere(1);
    let uv = |p: &Vec3| Vec2::new(0.5 + 0.5 * p.x, 0.5 - 0.5 * p.y);
    mesh.shading.uv[0] = mesh.positions.iter().map(uv).collect();
    mesh.shading.uv[1] = mesh.positions.iter().map(|p| uv(p) * 2.0).collect();
    let scene = one_object("round trip", Some(mesh.clone()), Environment::sky());
    let bytes = glb_bytes(&scene).expect("writes");
    let loaded = load_gltf_bytes(&bytes, "round-trip.glb", 1.0).expect("loads");
    let back = &loaded.meshes[0];
    // The loader keeps vertices in first use order: compare per corner of each triangle.
    assert_eq!(back.indices.len(), mesh.indices.len());
    for (t, (a, b)) in back.indices.iter().zip(&mesh.indices).enumerate() {
        for k in 0..3 {
            let (va, vb) = (a[k] as usize, b[k] as usize);
            assert_eq!(back.positions[va], mesh.positions[vb], "triangle {t}");
            assert!(
                back.shading.normals[va].abs_diff_eq(mesh.shading.normals[vb], 1e-6),
                "triangle {t} corner {k}: normal"
            );
            for set in 0..2 {
                assert_eq!(
                    back.shading.uv[set][va], mesh.shading.uv[set][vb],
                    "triangle {t} corner {k}: TEXCOORD_{set}"
                );
            }
        }
    }
    // And a mesh without them stays without them.
    let plain = one_object("plain", Some(icosphere(0)), Environment::sky());
    let loaded = load_gltf_bytes(&glb_bytes(&plain).unwrap(), "plain.glb", 1.0).unwrap();
    assert!(loaded.meshes[0].shading.is_empty());
}
