//! KHR_lights_punctual against their closed forms: a diffuse plane lit by a point light shows
//! a/π · I cos θ / r², by a spot the same times the extension's cone falloff, by a directional
//! light a/π · E cos θ, and by all of them together (with a bright light among dim ones, picked
//! in proportion to power) their sum. Punctual lights have no area, so next-event estimation of
//! one light is exact: what varies within a pixel is only where its samples land.

mod common;

use fovea::check::scale::quad;
use fovea::render::{regular_frame, Integrator, Renderer};
use fovea::scene::glb_write::glb_bytes;
use fovea::scene::gltf_load::load_gltf_bytes;
use fovea::scene::{Camera, Environment, Instance, LightKind, Material, PunctualLight, Scene};
use glam::{Mat4, Vec3};
use std::f32::consts::PI;

const ALBEDO: f32 = 0.5;
const SIZE: u32 = 32;

/// A large diffuse plane at y = 0 seen straight down from (0, 1, 0), lit by `lights` alone.
fn plane_under(lights: Vec<PunctualLight>) -> Scene {
    Scene {
        name: "punctual".into(),
        meshes: vec![quad()],
        instances: vec![Instance {
            mesh: 0,
            material: 0,
            transform: Mat4::from_scale(Vec3::new(50.0, 1.0, 50.0)),
        }],
        boxes: vec![],
        spheres: vec![],
        materials: vec![Material::diffuse(Vec3::splat(ALBEDO))],
        textures: vec![],
        camera: Camera::look_at(Vec3::Y, Vec3::ZERO, Vec3::NEG_Z, 70.0, 1.0),
        environment: Environment::black(),
        lights,
        environment_map: None,
        light_selection: Default::default(),
    }
}

fn light(kind: LightKind, intensity: Vec3, position: Vec3, direction: Vec3) -> PunctualLight {
    PunctualLight {
        kind,
        intensity,
        position,
        direction: direction.normalize(),
        range: None,
    }
}

/// Where the ray through point (x, y) of the image (in pixels from the top left) meets the
/// plane y = 0.
fn plane_point(camera: &Camera, x: f32, y: f32) -> Vec3 {
    let (right, up, forward) = camera.basis();
    let (l, r) = (camera.angle_left.tan(), camera.angle_right.tan());
    let (u, d) = (camera.angle_up.tan(), camera.angle_down.tan());
    let tx = l + x / SIZE as f32 * (r - l);
    let ty = u - y / SIZE as f32 * (u - d);
    let dir = forward + tx * right + ty * up;
    camera.position + dir * (-camera.position.y / dir.y)
}

/// The radiance a diffuse plane point p reflects from `light`, unoccluded.
fn analytic(light: &PunctualLight, p: Vec3) -> Vec3 {
    let irradiance = match light.kind {
        LightKind::Directional => light.intensity * (-light.direction).dot(Vec3::Y).max(0.0),
        _ => {
            let to = light.position - p;
            let r2 = to.length_squared();
            let wi = to / r2.sqrt();
            let cone = light.cone_falloff(light.direction.dot(-wi));
            light.intensity * cone * wi.y.max(0.0) / r2
        }
    };
    irradiance * ALBEDO / PI
}

fn render(scene: &Scene, spp: u32) -> fovea::render::Frame {
    let ctx = common::context();
    common::render(
        &ctx,
        scene,
        &common::settings(SIZE, SIZE, spp, 7, Integrator::Pt),
    )
}

/// The sum of the lights' closed forms averaged over pixel (x, y) (8 × 8 points: a pixel's
/// samples spread over its footprint).
fn pixel_closed_form(scene: &Scene, x: u32, y: u32) -> Vec3 {
    let mut sum = Vec3::ZERO;
    for k in 0..64 {
        let (sx, sy) = ((k % 8) as f32 + 0.5, (k / 8) as f32 + 0.5);
        let p = plane_point(&scene.camera, x as f32 + sx / 8.0, y as f32 + sy / 8.0);
        sum += scene.lights.iter().map(|l| analytic(l, p)).sum::<Vec3>();
    }
    sum / 64.0
}

/// Every block of `block` × `block` pixels within `tolerance` × the image's brightest
/// expected value of its closed form (blocks: light picked among several adds choice noise).
fn assert_matches_closed_form(scene: &Scene, spp: u32, block: u32, tolerance: f32) {
    let frame = render(scene, spp);
    let expected: Vec<Vec3> = (0..SIZE * SIZE)
        .map(|i| pixel_closed_form(scene, i % SIZE, i / SIZE))
        .collect();
    let peak = expected.iter().map(|v| v.max_element()).fold(0.0, f32::max);
    assert!(peak > 0.0);
    for (by, bx) in (0..SIZE / block).flat_map(|by| (0..SIZE / block).map(move |bx| (by, bx))) {
        let pixels = (0..block * block).map(|k| (bx * block + k % block, by * block + k / block));
        let (mut got, mut want) = (Vec3::ZERO, Vec3::ZERO);
        for (x, y) in pixels {
            got += Vec3::from(frame.pixel(x, y));
            want += expected[(y * SIZE + x) as usize];
        }
        let n = (block * block) as f32;
        let (got, want) = (got / n, want / n);
        assert!(
            (got - want).abs().max_element() <= tolerance * peak,
            "{}: block ({bx}, {by}): {got} vs closed form {want} (peak {peak})",
            scene.name
        );
    }
}

#[test]
fn a_point_light_over_a_diffuse_plane_gives_intensity_cos_over_r_squared() {
    let point = light(
        LightKind::Point,
        Vec3::new(2.0, 1.0, 0.5),
        Vec3::new(0.3, 0.8, -0.2),
        Vec3::NEG_Y,
    );
    assert_matches_closed_form(&plane_under(vec![point]), 16, 1, 0.02);
}

#[test]
fn a_spot_light_falls_off_as_the_extension_says() {
    let spot = light(
        LightKind::Spot {
            inner_cone_angle: 0.3,
            outer_cone_angle: 0.6,
        },
        Vec3::splat(1.5),
        Vec3::new(0.0, 0.7, 0.0),
        Vec3::new(0.1, -1.0, 0.0),
    );
    // Within the cone, on its falloff and outside it: every pixel, the middle row among them.
    assert_matches_closed_form(&plane_under(vec![spot]), 256, 1, 0.02);
}

#[test]
fn a_directional_light_gives_lux_times_cos_and_casts_shadows() {
    let sun = light(
        LightKind::Directional,
        Vec3::new(3.0, 2.0, 1.0),
        Vec3::ZERO,
        Vec3::new(0.5, -1.0, 0.2),
    );
    let mut scene = plane_under(vec![sun]);
    assert_matches_closed_form(&scene, 4, 1, 1e-3);
    // A roof over everything (above the camera) takes all of it away.
    scene.instances.push(Instance {
        mesh: 0,
        material: 0,
        transform: Mat4::from_translation(Vec3::new(0.0, 2.0, 0.0))
            * Mat4::from_scale(Vec3::new(50.0, 1.0, 50.0)),
    });
    let frame = render(&scene, 4);
    assert_eq!(frame.mean(), [0.0; 3], "light came through the roof");
}

#[test]
fn a_bright_light_among_dim_ones_is_picked_by_power_and_the_sum_is_right() {
    // One bright point light, 30 dim lamps and a sun: chosen uniformly, 30 of 32 shadow rays
    // would go to lamps that add almost nothing; by power (the sun taking half as the one
    // light at infinity), the image is the sum of all of them.
    let mut lights = vec![light(
        LightKind::Point,
        Vec3::splat(3.0),
        Vec3::new(-0.2, 0.9, 0.1),
        Vec3::NEG_Y,
    )];
    for k in 0..30 {
        let angle = k as f32 * 0.7;
        let at = Vec3::new(angle.cos(), 0.3 + 0.02 * k as f32, angle.sin());
        lights.push(light(LightKind::Point, Vec3::splat(0.003), at, Vec3::NEG_Y));
    }
    lights.push(light(
        LightKind::Directional,
        Vec3::splat(0.2),
        Vec3::ZERO,
        Vec3::new(0.0, -1.0, 0.3),
    ));
    assert_matches_closed_form(&plane_under(lights), 256, 8, 0.03);
}

#[test]
fn the_seed_integrator_refuses_a_scene_it_cannot_light() {
    let point = light(LightKind::Point, Vec3::ONE, Vec3::Y, Vec3::NEG_Y);
    let scene = plane_under(vec![point]);
    let ctx = common::context();
    let mut renderer = Renderer::new(&ctx, &scene).unwrap();
    let settings = common::settings(8, 8, 1, 1, Integrator::Seed);
    let Err(error) = regular_frame(&mut renderer, &scene.camera, &settings) else {
        panic!("the seed integrator rendered punctual lights it cannot see");
    };
    let error = error.to_string();
    assert!(error.contains("--integrator pt"), "{error}");
}

#[test]
fn lights_survive_a_round_trip_through_gltf() {
    let mut spot = light(
        LightKind::Spot {
            inner_cone_angle: 0.1,
            outer_cone_angle: 0.7,
        },
        Vec3::new(4.0, 2.0, 1.0),
        Vec3::new(1.0, 2.0, 3.0),
        Vec3::new(0.3, -1.0, 0.2),
    );
    spot.range = Some(12.0);
    let sun = light(
        LightKind::Directional,
        Vec3::splat(5.0),
        Vec3::ZERO,
        Vec3::new(-0.4, -1.0, 0.0),
    );
    let scene = plane_under(vec![spot, sun]);
    let bytes = glb_bytes(&scene).unwrap();
    let loaded = load_gltf_bytes(&bytes, "lights.glb", 1.0).unwrap();
    assert_eq!(loaded.lights.len(), 2);
    for (a, b) in scene.lights.iter().zip(&loaded.lights) {
        assert_eq!(a.kind, b.kind);
        assert_eq!(a.range, b.range);
        assert!((a.intensity - b.intensity).abs().max_element() < 1e-5);
        assert!((a.direction - b.direction).length() < 1e-5);
        if a.kind != LightKind::Directional {
            assert!((a.position - b.position).length() < 1e-5);
        }
    }
}

#[test]
fn bad_lights_are_refused_with_what_to_fix() {
    let mut wide = light(
        LightKind::Spot {
            inner_cone_angle: 0.1,
            outer_cone_angle: 2.0,
        },
        Vec3::ONE,
        Vec3::Y,
        Vec3::NEG_Y,
    );
    let bytes = glb_bytes(&plane_under(vec![wide])).unwrap();
    let error = load_gltf_bytes(&bytes, "lights.glb", 1.0)
        .err()
        .unwrap()
        .to_string();
    assert!(
        error.contains("cone angles") && error.contains("π/2"),
        "{error}"
    );
    wide.kind = LightKind::Point;
    wide.intensity = Vec3::new(1.0, -2.0, 1.0);
    let bytes = glb_bytes(&plane_under(vec![wide])).unwrap();
    let error = load_gltf_bytes(&bytes, "lights.glb", 1.0)
        .err()
        .unwrap()
        .to_string();
    assert!(error.contains("negative"), "{error}");
}
