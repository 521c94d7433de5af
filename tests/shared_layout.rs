//! glsl/shared.h is the one source of struct layouts: this test parses its structs, lays them
//! out by the std430 rules, and checks every Rust mirror's size and field offsets against it.

use fovea::shader_layout::*;
use std::collections::HashMap;
use std::mem::{offset_of, size_of};

/// (size, alignment) of a std430 member type the header is allowed to use: scalars, vec2,
/// vec4, and structs defined above it (`known`: name → (size, alignment)).
fn std430(ty: &str, known: &HashMap<String, (usize, usize)>) -> (usize, usize) {
    match ty {
        "float" | "uint" | "int" => (4, 4),
        "vec2" | "uvec2" | "ivec2" => (8, 8),
        "vec4" | "uvec4" | "ivec4" => (16, 16),
        other => *known.get(other).unwrap_or_else(|| panic!("shared.h uses '{other}', which this layout check does not know; keep to scalars, vec2, vec4 and structs defined before")),
    }
}

/// Fields of a struct with their byte offsets.
type Fields = Vec<(String, usize)>;
/// A struct being parsed: name, fields so far, next offset, largest alignment.
type Open = (String, Fields, usize, usize);

/// struct name → [(field, offset)] and total size, from the header text.
fn parse_header() -> HashMap<String, (Fields, usize)> {
    let text =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/glsl/shared.h")).unwrap();
    let mut structs = HashMap::new();
    // (size, alignment) of the structs parsed so far, which later structs may contain.
    let mut known = HashMap::new();
    let mut current: Option<Open> = None;
    for line in text.lines() {
        let line = line.split("//").next().unwrap().trim();
        if let Some(name) = line
            .strip_prefix("struct ")
            .and_then(|l| l.strip_suffix('{'))
        {
            current = Some((name.trim().to_string(), Vec::new(), 0, 4));
        } else if line.starts_with("};") {
            let (name, fields, offset, align) =
                current.take().expect("closing brace without struct");
            let size = offset.div_ceil(align) * align;
            known.insert(name.clone(), (size, align));
            structs.insert(name, (fields, size));
        } else if let Some((_, fields, offset, align)) = current.as_mut() {
            let words: Vec<_> = line.trim_end_matches(';').split_whitespace().collect();
            if let [ty, field] = words[..] {
                let (size, a) = std430(ty, &known);
                *offset = offset.div_ceil(a) * a;
                fields.push((field.to_string(), *offset));
                *offset += size;
                *align = (*align).max(a);
            }
        }
    }
    structs
}

macro_rules! check {
    ($structs:expr, $ty:ident { $($field:ident),* $(,)? }) => {{
        let (fields, size) = $structs.get(stringify!($ty)).unwrap_or_else(|| panic!("{} missing from shared.h", stringify!($ty)));
        assert_eq!(size_of::<$ty>(), *size, "size of {}", stringify!($ty));
        let rust: Vec<(String, usize)> = vec![$((stringify!($field).to_string(), offset_of!($ty, $field))),*];
        assert_eq!(&rust, fields, "fields and offsets of {}", stringify!($ty));
    }};
}

#[test]
fn rust_mirrors_match_shared_h_std430_layout() {
    let s = parse_header();
    check!(s, GpuTriangle { v0, v1, v2 });
    check!(
        s,
        GpuTriangleShading {
            normals,
            uv0_01,
            uv0_2_uv1_0,
            uv1_12,
            tangents
        }
    );
    check!(
        s,
        GpuObject {
            world_to_object0,
            world_to_object1,
            world_to_object2,
            object_to_world0,
            object_to_world1,
            object_to_world2,
            a,
            b,
            kind,
            material,
            blas_root,
            triangle_base,
            emitter,
            triangle_count,
            surface,
            alpha_cutoff
        }
    );
    check!(
        s,
        GpuMaterial {
            kd,
            ks,
            emission,
            base_color,
            metallic,
            roughness,
            model,
            normal_scale,
            base_color_texture,
            metallic_roughness_texture,
            emissive_texture,
            normal_texture
        }
    );
    check!(
        s,
        GpuTextureSlot {
            u_row,
            v_row,
            texture,
            texcoord,
            pad0,
            pad1
        }
    );
    check!(
        s,
        GpuEmitter {
            p0,
            p1,
            p2,
            emission,
            kind,
            object,
            alias,
            keep,
            pmf,
            range,
            spot_scale,
            spot_offset
        }
    );
    check!(
        s,
        GpuSceneInfo {
            sky_zenith,
            sky_horizon,
            sky_ground,
            emitter_count,
            object_count,
            tlas_node_count,
            tlas_root,
            env_width,
            env_height,
            env_rotate_cos,
            env_rotate_sin,
            env_pmf,
            pad0,
            pad1,
            pad2
        }
    );
    check!(
        s,
        PushCamera {
            position,
            right,
            up,
            forward,
            tan
        }
    );
    check!(
        s,
        PushEye {
            width,
            height,
            index,
            seed,
            layer_base,
            layer_count,
            work_stride,
            history,
            debug
        }
    );
    check!(
        s,
        EyePush {
            cam,
            eye,
            albedo,
            lattice_base,
            pad2
        }
    );
    check!(
        s,
        DenoisePush {
            cam,
            eye,
            iteration,
            pad0,
            last
        }
    );
    check!(
        s,
        AccumulatePush {
            cam,
            eye,
            mean_layer,
            frames_before,
            pad0
        }
    );
    check!(s, RaycastPush { probe_count });
    check!(s, BrdfProbePush { query_count });
    check!(
        s,
        DisplayPush {
            width,
            height,
            scale,
            tonemap
        }
    );
    check!(
        s,
        GpuBrdfQuery {
            wo,
            wi,
            u,
            material,
            pad0,
            pad1,
            pad2
        }
    );
    check!(
        s,
        GpuBrdfAnswer {
            sampled,
            weight,
            value
        }
    );
    check!(
        s,
        GpuLayer {
            gaze,
            plan_cos,
            resolve_cos,
            pixel_tan,
            anchor_x,
            anchor_y,
            spacing,
            spp,
            box_i0,
            box_j0,
            box_cols,
            box_rows,
            col_min,
            row_min,
            cols,
            first,
            box_prefix,
            mask_plane,
            outer,
            plan_runs,
            denoise,
            filter_mar,
            filter_px,
            denoise_mar,
            fraction,
            fraction_phase,
            lanes,
            lane_unit,
            denoise_sigma,
            pad0,
            pad1,
            pad2
        }
    );
    check!(s, GpuProbeRay { origin, direction });
    check!(
        s,
        GpuHistoryView {
            position,
            right,
            up,
            forward,
            tan,
            valid,
            moved,
            cap,
            pad0
        }
    );
    check!(
        s,
        GpuProbeHit {
            t,
            object,
            primitive,
            overflow
        }
    );
    assert_eq!(
        s.len(),
        21,
        "shared.h has a struct this test does not check: add it"
    );
    for (name, size) in [
        ("EyePush", size_of::<EyePush>()),
        ("DenoisePush", size_of::<DenoisePush>()),
        ("AccumulatePush", size_of::<AccumulatePush>()),
        ("RaycastPush", size_of::<RaycastPush>()),
        ("BrdfProbePush", size_of::<BrdfProbePush>()),
        ("DisplayPush", size_of::<DisplayPush>()),
    ] {
        assert!(
            size <= 128,
            "{name} must fit the guaranteed 128 push-constant bytes"
        );
    }
}

#[test]
fn binding_numbers_come_from_shared_h() {
    // build.rs generates these from the header's #defines; spot-check two against the text.
    let text =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/glsl/shared.h")).unwrap();
    assert!(text.contains(&format!("#define BINDING_OUTPUT {BINDING_OUTPUT} ")));
    assert!(text.contains(&format!(
        "#define TRAVERSAL_STACK_SIZE {TRAVERSAL_STACK_SIZE}"
    )));
    // NO_LIMIT is a float, which build.rs does not generate: the Rust copy must match.
    let line = text
        .lines()
        .find(|l| l.starts_with("#define NO_LIMIT "))
        .expect("NO_LIMIT in shared.h");
    let value: f32 = line.split_whitespace().nth(2).unwrap().parse().unwrap();
    assert_eq!(value, NO_LIMIT);
}
