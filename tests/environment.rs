//! HDR environments: the map's orientation as the shaders read it, a diffuse sphere in a
//! constant environment (albedo × environment, in closed form), a floor under the sunset
//! against its irradiance integrated here, and importance sampling that changes the noise, not
//! the mean.

mod common;

use std::path::Path;
use std::sync::Arc;

use fovea::render::{Frame, Integrator};
use fovea::scene::env_map::uv_to_direction;
use fovea::scene::{
    Camera, EnvSampling, Environment, EnvironmentLight, EnvironmentMap, Instance, Material, Scene,
    Sphere,
};
use glam::{Mat3, Mat4, Vec3};

fn scene(camera: Camera, env: EnvironmentLight) -> Scene {
    Scene {
        name: "environment".into(),
        meshes: vec![],
        instances: vec![],
        boxes: vec![],
        spheres: vec![],
        materials: vec![],
        textures: vec![],
        camera,
        environment: Environment::black(),
        lights: vec![],
        environment_map: Some(env),
        light_selection: Default::default(),
    }
}

fn light(map: EnvironmentMap, rotate_deg: f32, sampling: EnvSampling) -> EnvironmentLight {
    EnvironmentLight {
        map: Arc::new(map),
        rotate_deg,
        intensity: 1.0,
        sampling,
    }
}

fn render(scene: &Scene, size: u32, spp: u32, seed: u32) -> Frame {
    let ctx = common::context();
    common::render(
        &ctx,
        scene,
        &common::settings(size, size, spp, seed, Integrator::Pt),
    )
}

#[test]
fn a_camera_sees_the_texel_its_direction_names_turned_by_the_rotation() {
    // 8 × 4 texels, each its own colour: (column + 1, row + 1, 1) / 10.
    let (w, h) = (8u32, 4u32);
    let texels = (0..w * h)
        .map(|i| Vec3::new((i % w + 1) as f32, (i / w + 1) as f32, 1.0) * 0.1)
        .collect();
    let map = EnvironmentMap::from_texels(Path::new("colours.exr"), w, h, texels).unwrap();
    let map = Arc::new(map);
    for rotate in [0.0f32, 90.0, -35.0] {
        for (col, row) in [(2u32, 1u32), (5, 2), (0, 3), (7, 0)] {
            let (u, t) = ((col as f32 + 0.5) / w as f32, (row as f32 + 0.5) / h as f32);
            let turned = Mat3::from_rotation_y(rotate.to_radians()) * uv_to_direction(u, t);
            let camera = Camera::look_at(Vec3::ZERO, turned, up_for(turned), 1.0, 1.0);
            let env = EnvironmentLight {
                map: map.clone(),
                rotate_deg: rotate,
                intensity: 1.0,
                sampling: EnvSampling::Importance,
            };
            let frame = render(&scene(camera, env), 9, 4, 1);
            let seen = Vec3::from(frame.pixel(4, 4));
            let texel = Vec3::new(col as f32 + 1.0, row as f32 + 1.0, 1.0) * 0.1;
            assert!(
                (seen - texel).abs().max_element() < 2e-3,
                "rotate {rotate}: texel ({col}, {row}) is {texel}, the camera saw {seen}"
            );
        }
    }
}

/// An up vector not parallel to `forward`.
fn up_for(forward: Vec3) -> Vec3 {
    if forward.y.abs() > 0.9 {
        Vec3::Z
    } else {
        Vec3::Y
    }
}

#[test]
fn a_diffuse_sphere_in_a_constant_environment_shows_albedo_times_it() {
    // Convex: the sphere sees only the environment, so every point reflects a·L exactly.
    let l = Vec3::new(1.0, 0.6, 0.3);
    let a = 0.7;
    for sampling in [EnvSampling::Importance, EnvSampling::Uniform] {
        let map = EnvironmentMap::from_texels(Path::new("grey.exr"), 16, 8, vec![l; 128]);
        let camera = Camera::look_at(Vec3::new(0.0, 0.0, 3.0), Vec3::ZERO, Vec3::Y, 30.0, 1.0);
        let mut s = scene(camera, light(map.unwrap(), 30.0, sampling));
        s.materials.push(Material::diffuse(Vec3::splat(a)));
        s.spheres.push(Sphere {
            center: Vec3::ZERO,
            radius: 0.6,
            material: 0,
        });
        let frame = render(&s, 16, 256, 3);
        // Pixels wholly on the sphere (the middle 6 × 6) and wholly off it (the corners).
        for (x, y) in (5..11).flat_map(|y| (5..11).map(move |x| (x, y))) {
            let got = Vec3::from(frame.pixel(x, y));
            // 256 samples of a cosine-weighted estimate: a few percent of noise at most.
            assert!(
                ((got - a * l).abs() / (a * l)).max_element() < 0.05,
                "{sampling:?}: pixel ({x}, {y}) {got}, expected {}",
                a * l
            );
        }
        for (x, y) in [(0, 0), (15, 0), (0, 15), (15, 15)] {
            let got = Vec3::from(frame.pixel(x, y));
            assert!((got - l).abs().max_element() < 1e-4, "{got} vs {l}");
        }
    }
}

fn blender_env(name: &str) -> EnvironmentMap {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("assets/env/{name}.exr"));
    EnvironmentMap::load(&path).unwrap()
}

/// A diffuse floor with a sphere on it under one of Blender's environments (CC0, assets/env/).
fn floor_and_sphere(env: &str, sampling: EnvSampling) -> Scene {
    let camera = Camera::look_at(Vec3::new(0.0, 1.5, 3.0), Vec3::ZERO, Vec3::Y, 40.0, 1.0);
    let mut s = scene(camera, light(blender_env(env), 0.0, sampling));
    s.meshes.push(fovea::check::scale::quad());
    s.materials.push(Material::diffuse(Vec3::splat(0.6)));
    s.instances.push(Instance {
        mesh: 0,
        material: 0,
        transform: Mat4::from_scale(Vec3::new(20.0, 1.0, 20.0)),
    });
    s.spheres.push(Sphere {
        center: Vec3::new(0.0, 0.5, 0.0),
        radius: 0.5,
        material: 0,
    });
    s
}

fn relative_error(image: &[f32], reference: &[f32]) -> f64 {
    let num: f64 = (image.iter().zip(reference))
        .map(|(a, b)| ((a - b) as f64).powi(2))
        .sum();
    let den: f64 = reference.iter().map(|b| (*b as f64).powi(2)).sum();
    (num / den).sqrt()
}

#[test]
fn importance_sampling_keeps_the_mean_of_uniform_sampling() {
    // The courtyard (brightest texel 98× the mean), where uniform sampling converges too: both
    // agree per 8 × 8 block within their noise. (Under the sunset, uniform sampling finds the
    // sun in a few samples of a million, so its mean at any affordable count is short by the
    // sun's share; the floor below checks that environment against the closed form instead.)
    const SIZE: u32 = 24;
    let a = render(
        &floor_and_sphere("courtyard", EnvSampling::Importance),
        SIZE,
        256,
        11,
    );
    let b = render(
        &floor_and_sphere("courtyard", EnvSampling::Uniform),
        SIZE,
        1024,
        12,
    );
    let (sa, sb) = (
        common::block_stats(&a.rgb, SIZE as usize, 8),
        common::block_stats(&b.rgb, SIZE as usize, 8),
    );
    for (block, (x, y)) in sa.iter().zip(&sb).enumerate() {
        for c in 0..3 {
            let (ma, ea) = x[c];
            let (mb, eb) = y[c];
            assert!(
                (ma - mb).abs() <= 4.0 * (ea * ea + eb * eb).sqrt(),
                "block {block} channel {c}: importance {ma} ± {ea}, uniform {mb} ± {eb}"
            );
        }
    }
}

/// The map's radiance at (u, t) as the shaders read it: bilinear, columns wrapping, rows
/// clamped.
fn bilinear(map: &EnvironmentMap, u: f64, t: f64) -> glam::DVec3 {
    let (w, h) = (map.width as i64, map.height as i64);
    let (x, y) = (u * w as f64 - 0.5, t * h as f64 - 0.5);
    let (x0, y0) = (x.floor() as i64, y.floor() as i64);
    let (fx, fy) = (x - x0 as f64, y - y0 as f64);
    let at = |c: i64, r: i64| {
        let c = c.rem_euclid(w);
        let r = r.clamp(0, h - 1);
        map.texels[(r * w + c) as usize].as_dvec3()
    };
    let top = at(x0, y0).lerp(at(x0 + 1, y0), fx);
    let bottom = at(x0, y0 + 1).lerp(at(x0 + 1, y0 + 1), fx);
    top.lerp(bottom, fy)
}

#[test]
fn a_floor_under_the_sunset_reflects_its_irradiance() {
    // An endless diffuse floor seen from above receives E = ∫ L cos θ dω from the upper
    // hemisphere (integrated here on a grid 4× finer than the map) and shows a/π · E.
    let albedo = 0.6;
    let map = blender_env("sunset");
    let (nu, nt) = (4 * map.width as usize, 2 * map.height as usize);
    let mut irradiance = glam::DVec3::ZERO;
    for j in 0..nt {
        let t = 0.5 * (j as f64 + 0.5) / nt as f64; // upper hemisphere: t < 1/2
        let theta = t * std::f64::consts::PI;
        let d_omega = theta.sin()
            * (std::f64::consts::PI / 2.0 / nt as f64)
            * (2.0 * std::f64::consts::PI / nu as f64);
        for i in 0..nu {
            let u = (i as f64 + 0.5) / nu as f64;
            irradiance += bilinear(&map, u, t) * theta.cos() * d_omega;
        }
    }
    let expected = irradiance * albedo / std::f64::consts::PI;
    let camera = Camera::look_at(Vec3::Y, Vec3::ZERO, Vec3::NEG_Z, 60.0, 1.0);
    let mut s = scene(camera, light(map, 70.0, EnvSampling::Importance));
    s.meshes.push(fovea::check::scale::quad());
    s.materials
        .push(Material::diffuse(Vec3::splat(albedo as f32)));
    s.instances.push(Instance {
        mesh: 0,
        material: 0,
        transform: Mat4::from_scale(Vec3::new(1e4, 1.0, 1e4)),
    });
    let mean = render(&s, 16, 256, 5).mean();
    for c in 0..3 {
        assert!(
            (mean[c] - expected[c]).abs() < 0.01 * expected[c],
            "channel {c}: {} rendered, {} integrated",
            mean[c],
            expected[c]
        );
    }
}

#[test]
fn importance_sampling_cuts_the_error_where_the_light_is_concentrated() {
    // Error at 16 spp against the importance-sampled image at 4096, for the environments whose
    // light is concentrated: their 40 brightest texels hold 37% (interior), 45% (night) and
    // 60% (sunrise) of the light (luminance × sin θ). Measured: 11×, 6× and 6× lower error.
    // (The sunset's sun holds 2.4% of its light, almost none of it on a floor 3° below it:
    // there the broad sky decides and the gain is 1.3×, as for the courtyard's 2.3×.)
    const SIZE: u32 = 24;
    for env in ["interior", "night", "sunrise"] {
        let importance = floor_and_sphere(env, EnvSampling::Importance);
        let uniform = floor_and_sphere(env, EnvSampling::Uniform);
        let reference = render(&importance, SIZE, 4096, 13);
        let ea = relative_error(&render(&importance, SIZE, 16, 21).rgb, &reference.rgb);
        let eb = relative_error(&render(&uniform, SIZE, 16, 21).rgb, &reference.rgb);
        assert!(
            eb >= 4.0 * ea,
            "{env}, 16 spp: relative error {ea:.4} with importance sampling, {eb:.4} uniform"
        );
    }
}

#[test]
fn bad_environment_files_are_refused_with_what_to_do() {
    let dir = common::test_dir("env-bad-input");
    let write = |name: &str, w: u32, h: u32, value: f32| {
        let path = dir.join(name);
        let rgb = vec![value; (3 * w * h) as usize];
        fovea::render::output::write_rgb_exr(&path, w, h, &rgb).unwrap();
        path
    };
    let garbage = dir.join("garbage.exr");
    std::fs::write(&garbage, b"not an image at all").unwrap();
    let cases = [
        (write("square.exr", 8, 8, 1.0), "twice as wide"),
        (write("nan.exr", 8, 4, f32::NAN), "NaN or infinite"),
        (garbage, "not a readable OpenEXR image"),
        (
            dir.join("sky.png"),
            "must be an equirectangular .exr or .hdr",
        ),
        (dir.join("missing.hdr"), "cannot open it"),
    ];
    for (path, says) in cases {
        let (ok, text) = common::fovea(&[
            "render",
            "--scene",
            "cornell",
            "--env",
            path.to_str().unwrap(),
            "--width",
            "8",
            "--height",
            "8",
            "--out",
            common::SCRATCH_PNG,
        ]);
        assert!(!ok, "{}: accepted\n{text}", path.display());
        assert!(text.contains(says), "{}: {text}", path.display());
    }
}

#[test]
fn a_black_environment_is_no_light_for_next_event_estimation() {
    use fovea::scene::gpu_layout::GpuScene;
    use fovea::shader_layout::KIND_ENVIRONMENT;
    let camera = Camera::look_at(Vec3::Y, Vec3::ZERO, Vec3::NEG_Z, 60.0, 1.0);
    for (value, intensity, is_light) in [(0.0, 1.0, false), (1.0, 0.0, false), (1.0, 1.0, true)] {
        let map =
            EnvironmentMap::from_texels(Path::new("e.exr"), 8, 4, vec![Vec3::splat(value); 32]);
        let mut env = light(map.unwrap(), 0.0, EnvSampling::Importance);
        env.intensity = intensity;
        let mut s = scene(camera, env);
        s.meshes.push(fovea::check::scale::quad());
        s.materials.push(Material::diffuse(Vec3::splat(0.5)));
        s.instances.push(Instance {
            mesh: 0,
            material: 0,
            transform: Mat4::IDENTITY,
        });
        let gpu = GpuScene::build(&s).unwrap();
        let found = gpu.emitters.iter().any(|e| e.kind == KIND_ENVIRONMENT);
        assert_eq!(found, is_light, "texels {value}, intensity {intensity}");
        assert_eq!(gpu.info.env_pmf > 0.0, is_light);
    }
}

/// A scene that mixes every kind of light (emissive panel, point, spot, sun, environment)
/// renders through the foveated layers and, along a camera path, with the temporal history,
/// with nothing new: the fovea of a foveated frame is the regular frame's, pixel for pixel
/// (same seed and spp), and four still frames of history have the regular image's mean.
#[test]
fn foveated_and_temporal_frames_take_every_kind_of_light() {
    let dir = common::test_dir("env-foveated");
    let scene = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/assets/gltf/punctual-lights.glb"
    );
    let courtyard = concat!(env!("CARGO_MANIFEST_DIR"), "/assets/env/courtyard.exr");
    let path = dir.join("path.csv");
    let still: String = (0..4).map(|k| format!("{k},0,0,0,0,0,0\n")).collect();
    std::fs::write(
        &path,
        format!("frame,dx,dy,dz,yaw_deg,pitch_deg,roll_deg\n{still}"),
    )
    .unwrap();
    let render = |name: &str, extra: &[&str]| -> Vec<[f32; 3]> {
        let out = dir.join(name);
        let target = match name {
            "temporal" => out.clone(),
            _ => out.with_extension("exr"),
        };
        let args = [
            &["render", "--scene", scene, "--env", courtyard][..],
            &["--width", "64", "--height", "64", "--seed", "3"],
            extra,
            &["--out", target.to_str().unwrap()],
        ]
        .concat();
        let (ok, text) = common::fovea(&args);
        assert!(ok, "{name}: {text}");
        let exr = match name {
            "temporal" => out.join("frame_0003.exr"),
            _ => target,
        };
        let image = exr::prelude::read_first_rgba_layer_from_file(
            exr,
            |size, _| vec![[0.0f32; 3]; size.width() * size.height()],
            |px: &mut Vec<[f32; 3]>, pos, (r, g, b, _a): (f32, f32, f32, f32)| {
                px[pos.y() * 64 + pos.x()] = [r, g, b];
            },
        )
        .unwrap();
        let px = image.layer_data.channel_data.pixels;
        assert!(px.iter().flatten().all(|c| c.is_finite()), "{name}");
        px
    };
    let regular = render("regular", &["--spp", "16"]);
    let foveated = render(
        "foveated",
        &["--foveation", "thesis", "--gaze", "32,32", "--spp", "16"],
    );
    // The fovea (6° of a 45° view: about 8 pixels around the gaze) is traced at every pixel.
    for (y, x) in (28..36).flat_map(|y| (28..36).map(move |x| (y, x))) {
        assert_eq!(
            foveated[y * 64 + x],
            regular[y * 64 + x],
            "pixel ({x}, {y})"
        );
    }
    let mean = |px: &[[f32; 3]]| {
        px.iter().flatten().map(|&c| c as f64).sum::<f64>() / (3 * px.len()) as f64
    };
    let history = render(
        "temporal",
        &["--spp", "16", "--camera-path", path.to_str().unwrap()],
    );
    let (m, r) = (mean(&history), mean(&regular));
    assert!(
        (m - r).abs() < 0.03 * r,
        "four frames of history: mean {m}, regular {r}"
    );
}
