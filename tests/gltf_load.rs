//! glTF loading and GLB writing: a write → load round trip, the error for each kind of broken
//! file (each must name the file and the problem, and never panic), node hierarchies, strips
//! and fans, mesh deduplication, the bundled bunny assets, and a mutation sweep over a valid
//! .glb that must never panic.

mod common;

use std::path::{Path, PathBuf};

use fovea::scene::glb_write::{glb_bytes, write_glb};
use fovea::scene::gltf_load::{load_gltf, mesh_from_glb_bytes};
use fovea::scene::{
    Camera, Coverage, Environment, Instance, Material, Mesh, MetallicRoughness, Scene, SceneError,
};
use glam::{Mat4, Quat, Vec3};

const ASPECT: f32 = 16.0 / 9.0;

/// A fresh directory of this test's own, removed on drop.
fn temp_dir(test: &str) -> common::TestDir {
    common::test_dir(&format!("gltf-{test}"))
}

/// Standard base64 with padding (enough for `data:` URIs in hand-written test files).
fn base64(bytes: &[u8]) -> String {
    const TABLE: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::new();
    for chunk in bytes.chunks(3) {
        let b = [
            chunk[0],
            *chunk.get(1).unwrap_or(&0),
            *chunk.get(2).unwrap_or(&0),
        ];
        let n = (b[0] as u32) << 16 | (b[1] as u32) << 8 | b[2] as u32;
        for k in 0..4 {
            if k <= chunk.len() {
                out.push(TABLE[(n >> (18 - 6 * k) & 63) as usize] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}

/// Little-endian bytes of positions followed by u32 indices: the layout of [`gltf_text`].
fn geometry_bytes(positions: &[[f32; 3]], indices: &[u32]) -> Vec<u8> {
    let mut bytes: Vec<u8> = positions
        .iter()
        .flatten()
        .flat_map(|c| c.to_le_bytes())
        .collect();
    bytes.extend(indices.iter().flat_map(|i| i.to_le_bytes()));
    bytes
}

/// A .gltf with one buffer at `uri` (laid out by [`geometry_bytes`]), one primitive of `mode`
/// and the given `nodes` JSON (the scene's roots are `roots`).
fn gltf_text(
    positions: &[[f32; 3]],
    indices: &[u32],
    mode: u32,
    uri: &str,
    nodes: &str,
    roots: &str,
) -> String {
    let finite = positions
        .iter()
        .flatten()
        .copied()
        .filter(|c| c.is_finite());
    let (min, max) = (
        finite.clone().fold(f32::MAX, f32::min),
        finite.fold(f32::MIN, f32::max),
    );
    let position_bytes = positions.len() * 12;
    format!(
        r#"{{
  "asset": {{ "version": "2.0" }},
  "scene": 0,
  "scenes": [{{ "nodes": {roots} }}],
  "nodes": {nodes},
  "meshes": [{{ "name": "thing", "primitives": [{{ "attributes": {{ "POSITION": 0 }}, "indices": 1, "mode": {mode} }}] }}],
  "accessors": [
    {{ "bufferView": 0, "componentType": 5126, "count": {}, "type": "VEC3", "min": [{min}, {min}, {min}], "max": [{max}, {max}, {max}] }},
    {{ "bufferView": 1, "componentType": 5125, "count": {}, "type": "SCALAR" }}
  ],
  "bufferViews": [
    {{ "buffer": 0, "byteOffset": 0, "byteLength": {position_bytes} }},
    {{ "buffer": 0, "byteOffset": {position_bytes}, "byteLength": {} }}
  ],
  "buffers": [{{ "byteLength": {}, "uri": "{uri}" }}]
}}"#,
        positions.len(),
        indices.len(),
        indices.len() * 4,
        position_bytes + indices.len() * 4,
    )
}

/// One node with the mesh, as the only root.
const ONE_NODE: &str = r#"[{ "mesh": 0 }]"#;

/// Writes a .gltf whose buffer is an embedded `data:` URI; returns its path.
fn write_embedded(
    dir: &Path,
    name: &str,
    positions: &[[f32; 3]],
    indices: &[u32],
    mode: u32,
    nodes: &str,
    roots: &str,
) -> PathBuf {
    let uri = format!(
        "data:application/octet-stream;base64,{}",
        base64(&geometry_bytes(positions, indices))
    );
    let path = dir.join(name);
    std::fs::write(
        &path,
        gltf_text(positions, indices, mode, &uri, nodes, roots),
    )
    .expect("write test file");
    path
}

const TRIANGLE: [[f32; 3]; 3] = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];

/// The error of loading `path`; asserts that its message names the file and contains `words`.
fn expect_error(path: &Path, words: &[&str]) -> SceneError {
    let err = match load_gltf(path, ASPECT) {
        Ok(scene) => panic!(
            "{} loaded ({} triangles) but should fail",
            path.display(),
            scene.triangle_count()
        ),
        Err(e) => e,
    };
    let message = err.to_string();
    let file = path
        .file_name()
        .and_then(|f| f.to_str())
        .expect("file name");
    assert!(
        message.contains(file),
        "message does not name the file {file}: {message}"
    );
    for word in words {
        assert!(message.contains(word), "message lacks '{word}': {message}");
    }
    err
}

/// World-space triangles of one instance.
fn world_triangles(scene: &Scene, instance: &Instance) -> Vec<[Vec3; 3]> {
    let mesh = &scene.meshes[instance.mesh as usize];
    mesh.indices
        .iter()
        .map(|t| {
            t.map(|i| {
                instance
                    .transform
                    .transform_point3(mesh.positions[i as usize])
            })
        })
        .collect()
}

fn round_trip_scene() -> Scene {
    let tri = Mesh {
        name: "tri".into(),
        positions: TRIANGLE.iter().map(|&p| Vec3::from(p)).collect(),
        indices: vec![[0, 1, 2]],
        shading: Default::default(),
    };
    let quad = Mesh {
        name: "quad".into(),
        positions: vec![
            Vec3::new(-1.0, -1.0, 0.2),
            Vec3::new(1.0, -1.0, 0.0),
            Vec3::new(1.0, 1.0, -0.3),
            Vec3::new(-1.0, 1.0, 0.1),
        ],
        indices: vec![[0, 1, 2], [0, 2, 3]],
        shading: Default::default(),
    };
    let gltf = |base_color, metallic, roughness, emission| {
        Material::MetallicRoughness(MetallicRoughness {
            base_color,
            metallic,
            roughness,
            emission,
            textures: Default::default(),
            coverage: Coverage::SOLID,
        })
    };
    let materials = vec![
        gltf(Vec3::new(0.8, 0.3, 0.2), 0.0, 0.5, Vec3::ZERO),
        gltf(Vec3::new(0.9, 0.8, 0.5), 1.0, 0.0, Vec3::ZERO),
        gltf(Vec3::splat(0.5), 0.0, 1.0, Vec3::new(5.0, 4.0, 3.0)),
        gltf(
            Vec3::new(0.2, 0.6, 0.9),
            0.3,
            0.25,
            Vec3::new(0.2, 0.1, 0.0),
        ),
    ];
    let transforms = [
        Mat4::from_scale_rotation_translation(
            Vec3::new(2.0, 0.5, 1.5),
            Quat::from_axis_angle(Vec3::new(1.0, 1.0, 0.0).normalize(), 0.7),
            Vec3::new(1.0, 2.0, 3.0),
        ),
        Mat4::from_scale_rotation_translation(
            Vec3::new(1.0, 3.0, 0.25),
            Quat::from_rotation_y(2.0),
            Vec3::new(-1.0, 0.0, 0.5),
        ),
        Mat4::from_scale_rotation_translation(
            Vec3::new(0.5, 0.5, 2.0),
            Quat::from_rotation_x(-0.4),
            Vec3::new(0.0, -1.0, -2.0),
        ),
        Mat4::from_scale_rotation_translation(
            Vec3::new(-1.0, 1.0, 1.0),
            Quat::from_rotation_z(0.3),
            Vec3::new(2.0, 0.0, 0.0),
        ),
    ];
    let instances = vec![
        Instance {
            mesh: 0,
            material: 0,
            transform: transforms[0],
        },
        Instance {
            mesh: 0,
            material: 2,
            transform: transforms[1],
        },
        Instance {
            mesh: 1,
            material: 1,
            transform: transforms[2],
        },
        Instance {
            mesh: 1,
            material: 3,
            transform: transforms[3],
        },
    ];
    Scene {
        name: "round-trip".into(),
        meshes: vec![tri, quad],
        instances,
        boxes: Vec::new(),
        spheres: Vec::new(),
        materials,
        textures: Vec::new(),
        camera: Camera::look_at(Vec3::new(0.5, 1.5, 6.0), Vec3::ZERO, Vec3::Y, 50.0, ASPECT),
        environment: Environment::sky(),
        lights: Vec::new(),
        environment_map: None,
        light_selection: Default::default(),
    }
}

fn assert_material_close(loaded: &Material, original: &Material, what: &str) {
    let (Material::MetallicRoughness(l), Material::MetallicRoughness(o)) = (loaded, original)
    else {
        panic!("{what}: {loaded:?} and {original:?} are not both glTF materials");
    };
    // Factors are written as JSON numbers and read back exactly; emission above 1 goes
    // through a division by its peak (KHR_materials_emissive_strength) and back.
    assert_eq!(l.base_color, o.base_color, "{what}");
    let e_tol = 1e-6 * o.emission.max_element().max(1.0);
    assert!(
        l.emission.abs_diff_eq(o.emission, e_tol),
        "{what}: {l:?} vs {o:?}"
    );
    assert_eq!(
        (l.metallic, l.roughness),
        (o.metallic, o.roughness),
        "{what}"
    );
}

#[test]
fn round_trip_preserves_geometry_materials_and_camera() {
    let dir = temp_dir("round-trip");
    let path = dir.join("round-trip.glb");
    let original = round_trip_scene();
    write_glb(&original, &path).expect("write glb");
    let loaded = load_gltf(&path, ASPECT).expect("load the written glb");

    assert_eq!(loaded.name, "round-trip");
    assert_eq!(loaded.instances.len(), original.instances.len());
    assert_eq!(loaded.triangle_count(), original.triangle_count());
    for (i, (a, b)) in loaded.instances.iter().zip(&original.instances).enumerate() {
        let (ta, tb) = (world_triangles(&loaded, a), world_triangles(&original, b));
        assert_eq!(ta.len(), tb.len(), "instance {i}: triangle count");
        for (t, (x, y)) in ta.iter().zip(&tb).enumerate() {
            for k in 0..3 {
                assert!(
                    x[k].abs_diff_eq(y[k], 1e-5),
                    "instance {i} triangle {t} vertex {k}: {} vs {}",
                    x[k],
                    y[k]
                );
            }
        }
        assert_material_close(
            &loaded.materials[a.material as usize],
            &original.materials[b.material as usize],
            &format!("instance {i} material"),
        );
    }
    let emissive = loaded.materials[loaded.instances[1].material as usize];
    assert!(
        emissive
            .emission()
            .abs_diff_eq(Vec3::new(5.0, 4.0, 3.0), 1e-3),
        "emission above 1 survives"
    );
    assert!(loaded
        .camera
        .position
        .abs_diff_eq(original.camera.position, 1e-4));
    assert!(loaded
        .camera
        .forward
        .abs_diff_eq(original.camera.forward, 1e-4));
    assert!((loaded.camera.angle_up - original.camera.angle_up).abs() < 1e-4);
    assert!((loaded.camera.angle_right - original.camera.angle_right).abs() < 1e-4);

    // glb_bytes and write_glb agree.
    assert_eq!(
        glb_bytes(&original).expect("bytes"),
        std::fs::read(&path).expect("read back")
    );
}

#[test]
fn malformed_json_is_reported() {
    let dir = temp_dir("malformed");
    let path = dir.join("broken.gltf");
    std::fs::write(
        &path,
        r#"{ "asset": { "version": "2.0" }, "nodes": [ { "mesh": 0 "#,
    )
    .unwrap();
    expect_error(&path, &["malformed JSON"]);
    let path = dir.join("not-gltf.gltf");
    std::fs::write(&path, r#"{ "hello": "world" }"#).unwrap();
    expect_error(&path, &["not a glTF 2.0 document"]);
}

#[test]
fn truncated_glb_is_reported() {
    let dir = temp_dir("truncated");
    let bytes = glb_bytes(&round_trip_scene()).expect("bytes");
    let path = dir.join("half.glb");
    std::fs::write(&path, &bytes[..bytes.len() / 2]).unwrap();
    expect_error(&path, &["truncated"]);
    let path = dir.join("empty.glb");
    std::fs::write(&path, b"").unwrap();
    expect_error(&path, &["not a binary glTF"]);
}

#[test]
fn missing_file_is_reported() {
    let dir = temp_dir("missing");
    let err = expect_error(&dir.join("nowhere.glb"), &["not found"]);
    assert!(matches!(err, SceneError::Load { .. }));
}

#[test]
fn missing_external_bin_is_reported() {
    let dir = temp_dir("missing-bin");
    let path = dir.join("scene.gltf");
    std::fs::write(
        &path,
        gltf_text(&TRIANGLE, &[0, 1, 2], 4, "geometry.bin", ONE_NODE, "[0]"),
    )
    .unwrap();
    expect_error(&path, &["geometry.bin", "not found"]);
    // With the .bin in place the same file loads.
    std::fs::write(
        dir.join("geometry.bin"),
        geometry_bytes(&TRIANGLE, &[0, 1, 2]),
    )
    .unwrap();
    let scene = load_gltf(&path, ASPECT).expect("loads with its .bin");
    assert_eq!(scene.triangle_count(), 1);
    assert_eq!(scene.name, "scene");
}

#[test]
fn index_out_of_range_is_reported() {
    let dir = temp_dir("index-range");
    let path = write_embedded(
        &dir,
        "bad-index.gltf",
        &TRIANGLE,
        &[0, 1, 7],
        4,
        ONE_NODE,
        "[0]",
    );
    expect_error(
        &path,
        &[
            "index 7",
            "out of range",
            "3 vertices",
            "mesh 'thing'",
            "primitive #0",
        ],
    );
}

#[test]
fn accessor_out_of_bounds_is_reported() {
    let dir = temp_dir("accessor-bounds");
    let text = gltf_text(&TRIANGLE, &[0, 1, 2], 4, "geometry.bin", ONE_NODE, "[0]").replace(
        r#""count": 3, "type": "VEC3""#,
        r#""count": 30, "type": "VEC3""#,
    );
    std::fs::write(
        dir.join("geometry.bin"),
        geometry_bytes(&TRIANGLE, &[0, 1, 2]),
    )
    .unwrap();
    let path = dir.join("bounds.gltf");
    std::fs::write(&path, text).unwrap();
    expect_error(&path, &["out of bounds", "accessor #0"]);
}

#[test]
fn nan_vertex_is_reported() {
    let dir = temp_dir("nan");
    let positions = [[0.0, 0.0, 0.0], [f32::NAN, 0.0, 0.0], [0.0, 1.0, 0.0]];
    let path = write_embedded(&dir, "nan.gltf", &positions, &[0, 1, 2], 4, ONE_NODE, "[0]");
    expect_error(&path, &["non-finite", "mesh 'thing'", "vertex 1"]);
    let positions = [[0.0, 0.0, 0.0], [1.0, f32::INFINITY, 0.0], [0.0, 1.0, 0.0]];
    let path = write_embedded(&dir, "inf.gltf", &positions, &[0, 1, 2], 4, ONE_NODE, "[0]");
    expect_error(&path, &["non-finite"]);
}

#[test]
fn points_only_is_reported() {
    let dir = temp_dir("points");
    let path = write_embedded(
        &dir,
        "points.gltf",
        &TRIANGLE,
        &[0, 1, 2],
        0,
        ONE_NODE,
        "[0]",
    );
    expect_error(&path, &["no triangles", "point or line"]);
}

#[test]
fn node_hierarchy_composes_transforms() {
    let dir = temp_dir("hierarchy");
    let s = std::f32::consts::FRAC_1_SQRT_2;
    // Parent translates by (1, 2, 3); child rotates 90° about Z: (1, 0, 0) → (0, 1, 0) → (1, 3, 3).
    let nodes = format!(
        r#"[{{ "name": "parent", "translation": [1, 2, 3], "children": [1] }},
            {{ "name": "child", "rotation": [0, 0, {s}, {s}], "mesh": 0 }}]"#
    );
    let path = write_embedded(
        &dir,
        "hierarchy.gltf",
        &TRIANGLE,
        &[0, 1, 2],
        4,
        &nodes,
        "[0]",
    );
    let scene = load_gltf(&path, ASPECT).expect("load");
    assert_eq!(scene.instances.len(), 1);
    let world = world_triangles(&scene, &scene.instances[0]);
    assert!(
        world[0][1].abs_diff_eq(Vec3::new(1.0, 3.0, 3.0), 1e-5),
        "got {}",
        world[0][1]
    );
    assert!(
        world[0][0].abs_diff_eq(Vec3::new(1.0, 2.0, 3.0), 1e-5),
        "got {}",
        world[0][0]
    );

    // A node that is its own ancestor is an error, not a hang or a stack overflow.
    let cyclic = r#"[{ "children": [1] }, { "children": [0], "mesh": 0 }]"#;
    let path = write_embedded(&dir, "cycle.gltf", &TRIANGLE, &[0, 1, 2], 4, cyclic, "[0]");
    expect_error(&path, &["cycle"]);
}

#[test]
fn shared_mesh_is_one_mesh_with_several_instances() {
    let dir = temp_dir("dedup");
    let nodes = r#"[{ "mesh": 0 }, { "mesh": 0, "translation": [3, 0, 0] }, { "mesh": 0, "scale": [2, 2, 2] }]"#;
    let path = write_embedded(
        &dir,
        "shared.gltf",
        &TRIANGLE,
        &[0, 1, 2],
        4,
        nodes,
        "[0, 1, 2]",
    );
    let scene = load_gltf(&path, ASPECT).expect("load");
    assert_eq!(scene.meshes.len(), 1);
    assert_eq!(scene.instances.len(), 3);
    assert!(scene
        .instances
        .iter()
        .all(|i| i.mesh == 0 && i.material == 0));
    // No material in the file: glTF's default material (every property at its default).
    assert_eq!(
        scene.materials,
        vec![Material::MetallicRoughness(MetallicRoughness {
            base_color: Vec3::ONE,
            metallic: 1.0,
            roughness: 1.0,
            emission: Vec3::ZERO,
            textures: Default::default(),
            coverage: Coverage::GLTF_DEFAULT,
        })]
    );
    // No camera in the file: the bounding box is framed and in front of the camera.
    let (min, max) = (Vec3::ZERO, Vec3::new(4.0, 2.0, 0.0));
    let to_centre = (0.5 * (min + max) - scene.camera.position).normalize();
    assert!(scene.camera.forward.abs_diff_eq(to_centre, 1e-4));
    assert!(
        scene.camera.position.z > 0.0 && scene.camera.position.y > 1.0,
        "from +Z, above"
    );
}

#[test]
fn strips_and_fans_become_triangle_lists() {
    let dir = temp_dir("strips");
    let square = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [1.0, 1.0, 0.0],
    ];
    let path = write_embedded(
        &dir,
        "strip.gltf",
        &square,
        &[0, 1, 2, 3],
        5,
        ONE_NODE,
        "[0]",
    );
    let scene = load_gltf(&path, ASPECT).expect("strip");
    assert_eq!(
        scene.meshes[0].indices,
        vec![[0, 1, 2], [1, 3, 2]],
        "odd strip triangles keep the winding"
    );
    let path = write_embedded(&dir, "fan.gltf", &square, &[0, 1, 3, 2], 6, ONE_NODE, "[0]");
    let scene = load_gltf(&path, ASPECT).expect("fan");
    let world = world_triangles(&scene, &scene.instances[0]);
    assert_eq!(world.len(), 2);
    for tri in world {
        let normal = (tri[1] - tri[0]).cross(tri[2] - tri[0]);
        assert!(normal.z > 0.0, "fan triangles are counter-clockwise");
    }
}

#[test]
fn bundled_bunnies_parse_from_memory() {
    let low = mesh_from_glb_bytes(include_bytes!("../assets/bunny-low.glb"), "bunny-low")
        .expect("bunny-low");
    assert_eq!(low.name, "bunny-low");
    assert_eq!(low.indices.len(), 876 / 3);
    let high = mesh_from_glb_bytes(include_bytes!("../assets/bunny-high.glb"), "bunny-high")
        .expect("bunny-high");
    assert_eq!(high.indices.len(), 14904 / 3);
    assert!(high
        .positions
        .iter()
        .all(|p| p.is_finite() && p.y >= -1e-6 && p.y <= 1.0 + 1e-6));

    let err = mesh_from_glb_bytes(b"definitely not a glb", "assets/junk.glb").expect_err("junk");
    assert!(err.to_string().contains("assets/junk.glb"), "{err}");
}

#[test]
fn mutated_glb_never_panics() {
    let valid = glb_bytes(&round_trip_scene()).expect("bytes");
    // Every truncation length (step 3) and thousands of single-byte corruptions, each of which
    // must give Ok or Err but never panic, hang or allocate absurdly.
    for len in (0..valid.len()).step_by(3) {
        let _ = mesh_from_glb_bytes(&valid[..len], "cut.glb");
    }
    let mut state = 0x2545_f491_4f6c_dd1du64;
    let mut next = || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        state
    };
    for _ in 0..4000 {
        let mut bytes = valid.clone();
        let at = (next() % bytes.len() as u64) as usize;
        // Digits in the JSON make counts, offsets and indices wrong while staying parseable.
        let replacement = match next() % 3 {
            0 => b"0123456789"[(next() % 10) as usize],
            1 => next() as u8,
            _ => 0xff,
        };
        bytes[at] = replacement;
        let _ = mesh_from_glb_bytes(&bytes, "mutated.glb");
    }
}

/// Collects formatted log lines from the current thread.
#[derive(Clone, Default)]
struct LogBuffer(std::sync::Arc<std::sync::Mutex<Vec<u8>>>);

impl std::io::Write for LogBuffer {
    fn write(&mut self, bytes: &[u8]) -> std::io::Result<usize> {
        self.0.lock().expect("log buffer").extend_from_slice(bytes);
        Ok(bytes.len())
    }
    fn flush(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}

#[test]
fn ignored_features_warn_once_per_kind() {
    let dir = temp_dir("warn-once");
    let three = r#"[{ "attributes": { "POSITION": 0 }, "indices": 1, "mode": 1 },
                    { "attributes": { "POSITION": 0 }, "indices": 1, "mode": 0 },
                    { "attributes": { "POSITION": 0 }, "indices": 1, "mode": 4 }]"#;
    let uri = format!(
        "data:application/octet-stream;base64,{}",
        base64(&geometry_bytes(&TRIANGLE, &[0, 1, 2]))
    );
    let text = gltf_text(
        &TRIANGLE,
        &[0, 1, 2],
        4,
        &uri,
        r#"[{ "mesh": 0 }, { "mesh": 0 }]"#,
        "[0, 1]",
    )
    .replace(
        r#"[{ "attributes": { "POSITION": 0 }, "indices": 1, "mode": 4 }]"#,
        three,
    )
    .replace(
        r#""scene": 0,"#,
        r#""scene": 0, "extensionsUsed": ["EXT_example_one", "EXT_example_two"],"#,
    );
    let path = dir.join("features.gltf");
    std::fs::write(&path, text).unwrap();

    let log = LogBuffer::default();
    let writer = log.clone();
    let subscriber = tracing_subscriber::fmt()
        .with_writer(move || writer.clone())
        .with_ansi(false)
        .with_max_level(tracing::Level::WARN)
        .finish();
    let scene =
        tracing::subscriber::with_default(subscriber, || load_gltf(&path, ASPECT)).expect("load");
    assert_eq!(
        scene.instances.len(),
        2,
        "the triangle primitive of both nodes"
    );
    assert_eq!(scene.meshes.len(), 1);

    let text = String::from_utf8(log.0.lock().unwrap().clone()).unwrap();
    let warnings: Vec<&str> = text.lines().filter(|l| l.contains("WARN")).collect();
    assert_eq!(
        warnings
            .iter()
            .filter(|l| l.contains("point and line"))
            .count(),
        1,
        "{text}"
    );
    assert_eq!(
        warnings
            .iter()
            .filter(|l| l.contains("EXT_example_one"))
            .count(),
        1,
        "{text}"
    );
    assert_eq!(
        warnings
            .iter()
            .filter(|l| l.contains("EXT_example_two"))
            .count(),
        1,
        "{text}"
    );
    assert_eq!(warnings.len(), 3, "{text}");
    assert!(
        warnings.iter().all(|l| l.contains("features.gltf")),
        "{text}"
    );
}

#[test]
fn normals_that_do_not_match_the_vertices_are_reported() {
    let dir = temp_dir("normal-count");
    let path = write_embedded(
        &dir,
        "normals.gltf",
        &TRIANGLE,
        &[0, 1, 2],
        4,
        ONE_NODE,
        "[0]",
    );
    // A NORMAL accessor of 2 entries (over the positions' bytes) for 3 vertices.
    let text = std::fs::read_to_string(&path).unwrap();
    let text = text
        .replace(
            r#""attributes": { "POSITION": 0 }"#,
            r#""attributes": { "POSITION": 0, "NORMAL": 2 }"#,
        )
        .replace(
            r#""type": "SCALAR" }"#,
            r#""type": "SCALAR" },
    { "bufferView": 0, "componentType": 5126, "count": 2, "type": "VEC3" }"#,
        );
    std::fs::write(&path, text).unwrap();
    expect_error(
        &path,
        &["NORMAL has 2 entries", "POSITION has 3", "mesh 'thing'"],
    );
}

#[test]
fn a_normal_map_without_tangents_gets_mikktspace_ones() {
    // The corpus seed: a quad with NORMAL and TEXCOORD_0 but no TANGENT, its material's
    // normalTexture at scale 0.5. The mesh is unwelded (a vertex per triangle corner) with a
    // tangent per corner along +u (+x here).
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/fuzz/corpus/gltf_load/seed-textures.gltf"
    );
    let scene = load_gltf(path.as_ref(), ASPECT).expect("load");
    let mesh = &scene.meshes[0];
    assert_eq!(mesh.positions.len(), 6);
    assert_eq!(mesh.shading.tangents.len(), 6);
    for t in &mesh.shading.tangents {
        assert!(t.truncate().abs_diff_eq(Vec3::X, 1e-5), "{t}");
    }
    let Material::MetallicRoughness(m) = scene.materials[0] else {
        panic!("{:?}", scene.materials[0]);
    };
    assert_eq!(m.textures.normal_scale, 0.5);
    assert!(m.textures.normal.is_some());
}

/// A quad with normals, tangents and uv, and a material using every texture slot (one with a
/// texture transform), alpha-masked and single-sided.
fn textured_round_trip_scene() -> Scene {
    use fovea::scene::{
        AlphaMode, MaterialTextures, TexelEncoding, Texture, TextureRef, TextureSampler, Wrap,
    };
    use glam::{Vec2, Vec4};
    // The shared quad (normals, uv, tangents), with a second uv set and flipped bitangents.
    let mut quad = fovea::scene::shapes::quad();
    quad.shading.uv[1] = vec![Vec2::new(0.5, 0.25); 4];
    quad.shading.tangents = vec![Vec4::new(1.0, 0.0, 0.0, -1.0); 4];
    let texture = |name: &str, encoding, sampler| Texture {
        name: name.into(),
        width: 3,
        height: 2,
        rgba8: (0..24).map(|i| (i * 10) as u8).collect(),
        encoding,
        sampler,
    };
    let nearest_clamped = TextureSampler {
        wrap_u: Wrap::ClampToEdge,
        wrap_v: Wrap::MirroredRepeat,
        mag_linear: false,
        min_linear: false,
        mipmaps: false,
    };
    let slot = |texture, texcoord, transform| {
        Some(TextureRef {
            texture,
            texcoord,
            transform,
        })
    };
    let (sin, cos) = 0.3f32.sin_cos();
    let moved = [[cos * 2.0, sin * 0.5, 0.25], [-sin * 2.0, cos * 0.5, -0.5]];
    let material = MetallicRoughness {
        textures: MaterialTextures {
            base_color: slot(0, 0, moved),
            metallic_roughness: slot(1, 1, TextureRef::IDENTITY),
            emissive: slot(0, 0, TextureRef::IDENTITY),
            normal: slot(1, 0, TextureRef::IDENTITY),
            normal_scale: 0.75,
        },
        coverage: Coverage {
            alpha: 0.5,
            mode: AlphaMode::Mask { cutoff: 0.25 },
            double_sided: false,
        },
        ..MetallicRoughness::factors(Vec3::new(0.5, 0.25, 1.0), 0.5, 0.75, Vec3::splat(2.0))
    };
    Scene {
        name: "textured".into(),
        meshes: vec![quad],
        instances: vec![Instance {
            mesh: 0,
            material: 0,
            transform: Mat4::IDENTITY,
        }],
        boxes: Vec::new(),
        spheres: Vec::new(),
        materials: vec![Material::MetallicRoughness(material)],
        textures: vec![
            texture("colour", TexelEncoding::Srgb, TextureSampler::DEFAULT),
            texture("data", TexelEncoding::Linear, nearest_clamped),
        ],
        camera: Camera::look_at(Vec3::new(0.0, 0.0, 4.0), Vec3::ZERO, Vec3::Y, 50.0, ASPECT),
        environment: Environment::sky(),
        lights: Vec::new(),
        environment_map: None,
        light_selection: Default::default(),
    }
}

#[test]
fn round_trip_preserves_textures_alpha_faces_and_tangents() {
    let original = textured_round_trip_scene();
    let bytes = glb_bytes(&original).expect("write glb");
    let loaded = fovea::scene::gltf_load::load_gltf_bytes(&bytes, "textured.glb", ASPECT)
        .expect("load the written glb");
    let (Material::MetallicRoughness(l), Material::MetallicRoughness(o)) =
        (&loaded.materials[0], &original.materials[0])
    else {
        panic!("glTF materials: {:?}", loaded.materials);
    };
    assert_eq!(l.coverage, o.coverage);
    assert_eq!(l.textures.normal_scale, o.textures.normal_scale);
    // The loader keys textures by (image, encoding): texture 0 is used as colour twice and
    // texture 1 as data twice, so the indices survive.
    let pairs = [
        (l.textures.base_color, o.textures.base_color),
        (l.textures.metallic_roughness, o.textures.metallic_roughness),
        (l.textures.emissive, o.textures.emissive),
        (l.textures.normal, o.textures.normal),
    ];
    for (k, (a, b)) in pairs.into_iter().enumerate() {
        let (a, b) = (a.expect("slot read back"), b.unwrap());
        assert_eq!((a.texture, a.texcoord), (b.texture, b.texcoord), "slot {k}");
        let close = (a
            .transform
            .iter()
            .flatten()
            .zip(b.transform.iter().flatten()))
        .all(|(x, y)| (x - y).abs() < 1e-6);
        assert!(close, "slot {k}: {:?} vs {:?}", a.transform, b.transform);
    }
    assert_eq!(loaded.textures.len(), 2);
    for (a, b) in loaded.textures.iter().zip(&original.textures) {
        assert_eq!(
            (a.width, a.height, &a.rgba8, a.encoding, a.sampler),
            (b.width, b.height, &b.rgba8, b.encoding, b.sampler),
            "texture '{}'",
            b.name
        );
    }
    let (ls, os) = (&loaded.meshes[0].shading, &original.meshes[0].shading);
    assert_eq!(
        (&ls.tangents, &ls.normals, &ls.uv),
        (&os.tangents, &os.normals, &os.uv)
    );
}
