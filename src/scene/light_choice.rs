//! `--light-selection`: how next-event estimation weighs the lights of every scene the process
//! loads (by power, or uniformly for comparison).

use std::sync::OnceLock;

use super::lights::LightSelection;

static CHOICE: OnceLock<LightSelection> = OnceLock::new();

/// `--light-selection`: the weighing of every scene loaded from now on. Returns false when one
/// was set already (the first stays).
pub fn set_light_selection(choice: LightSelection) -> bool {
    CHOICE.set(choice).is_ok()
}

/// Gives `scene` the weighing chosen for the process, if one was.
pub fn apply(scene: &mut super::Scene) {
    if let Some(choice) = CHOICE.get() {
        scene.light_selection = *choice;
    }
}
