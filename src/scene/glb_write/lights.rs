//! Punctual lights as `KHR_lights_punctual`: one light and one node per light, the node's −Z
//! turned onto the light's direction; colour × intensity split as intensity = the largest
//! channel, colour = the channels over it.

use glam::{Quat, Vec3};
use serde_json::{json, Value};

use crate::scene::{LightKind, PunctualLight};

/// The extension's `lights` array and one node per light (light i on node i of the result).
pub(super) fn lights_json(lights: &[PunctualLight]) -> (Vec<Value>, Vec<Value>) {
    let mut written = Vec::new();
    let mut nodes = Vec::new();
    for (i, light) in lights.iter().enumerate() {
        let intensity = light.intensity.max_element();
        let color = if intensity > 0.0 {
            light.intensity / intensity
        } else {
            Vec3::ONE
        };
        let mut value = json!({
            "color": color.to_array().to_vec(),
            "intensity": intensity,
        });
        let fields = value.as_object_mut().expect("a JSON object");
        let kind = match light.kind {
            LightKind::Point => "point",
            LightKind::Directional => "directional",
            LightKind::Spot {
                inner_cone_angle,
                outer_cone_angle,
            } => {
                fields.insert(
                    "spot".into(),
                    json!({ "innerConeAngle": inner_cone_angle, "outerConeAngle": outer_cone_angle }),
                );
                "spot"
            }
        };
        fields.insert("type".into(), json!(kind));
        if let Some(range) = light.range {
            fields.insert("range".into(), json!(range));
        }
        written.push(value);
        let rotation = Quat::from_rotation_arc(Vec3::NEG_Z, light.direction.normalize());
        nodes.push(json!({
            "name": format!("light {i}"),
            "translation": light.position.to_array().to_vec(),
            "rotation": rotation.to_array().to_vec(),
            "extensions": { "KHR_lights_punctual": { "light": i } },
        }));
    }
    (written, nodes)
}
