//! Emissive surfaces as next-event estimation's area lights: every world-space triangle of an
//! emissive mesh instance, and each emissive box or sphere (GpuEmitter), unless their emission
//! varies across them.

use super::Material;
use crate::shader_layout::*;
use glam::{Mat4, Vec3};

fn v4(v: Vec3, w: f32) -> [f32; 4] {
    [v.x, v.y, v.z, w]
}

/// Emission that varies across the surface, which next-event estimation (one radiance per
/// emitter, over its whole area) does not know: an emissive texture, or alpha that cuts
/// holes in the emitter.
pub(super) fn emits_unevenly(m: &Material) -> bool {
    matches!(m, Material::MetallicRoughness(m)
        if m.textures.emissive.is_some() || m.coverage.cuts_out())
}

/// Emissive objects become NEE emitters: every world-space triangle of an emissive instance
/// (in the same leaf order as TRIANGLES, so hit triangle → emitter is an offset), and each
/// emissive box or sphere. Sets `GpuObject::emitter` to the first emitter of each object.
pub(super) fn collect_emitters(
    objects: &mut [GpuObject],
    triangles: &[GpuTriangle],
    materials: &[Material],
) -> Vec<GpuEmitter> {
    let mut emitters = Vec::new();
    for (index, ob) in objects.iter_mut().enumerate() {
        let m = &materials[ob.material as usize];
        // Uneven emission is found by BRDF sampling alone, with weight 1 (unbiased; noisier
        // for small bright ones).
        if !m.is_emissive() || emits_unevenly(m) {
            continue;
        }
        ob.emitter = emitters.len() as u32;
        let emission = |area: f32| v4(m.emission(), area);
        match ob.kind {
            KIND_INSTANCE => {
                let to_world = Mat4::from_cols_array_2d(&[
                    ob.object_to_world0,
                    ob.object_to_world1,
                    ob.object_to_world2,
                    [0.0, 0.0, 0.0, 1.0],
                ])
                .transpose();
                let mirrored = to_world.determinant() < 0.0;
                let first = ob.triangle_base as usize;
                for t in &triangles[first..first + ob.triangle_count as usize] {
                    let p = |v: [f32; 4]| to_world.transform_point3(Vec3::new(v[0], v[1], v[2]));
                    // A mirroring transform reverses the winding; swap two vertices so the
                    // emitter's front side stays the image of the object's front side, as the
                    // shaders' inverse-transpose normals (and glTF's winding rule) have it.
                    let (a, b, c) = if mirrored {
                        (p(t.v0), p(t.v2), p(t.v1))
                    } else {
                        (p(t.v0), p(t.v1), p(t.v2))
                    };
                    let area = 0.5 * (b - a).cross(c - a).length();
                    emitters.push(GpuEmitter {
                        p0: v4(a, 0.0),
                        p1: v4(b, 0.0),
                        p2: v4(c, 0.0),
                        emission: emission(area.max(1e-30)),
                        kind: KIND_TRIANGLE,
                        object: index as u32,
                        ..Default::default()
                    });
                }
            }
            KIND_BOX => {
                let e = Vec3::from_slice(&ob.b[..3]) - Vec3::from_slice(&ob.a[..3]);
                let area = 2.0 * (e.x * e.y + e.y * e.z + e.x * e.z);
                emitters.push(GpuEmitter {
                    p0: ob.a,
                    p1: ob.b,
                    emission: emission(area.max(1e-30)),
                    kind: KIND_BOX,
                    object: index as u32,
                    ..Default::default()
                });
            }
            _ => {
                let r = ob.a[3];
                emitters.push(GpuEmitter {
                    p0: ob.a,
                    emission: emission(4.0 * std::f32::consts::PI * r * r),
                    kind: KIND_SPHERE,
                    object: index as u32,
                    ..Default::default()
                });
            }
        }
    }
    emitters
}
