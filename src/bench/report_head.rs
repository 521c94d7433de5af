//! What heads every report of a run, still or motion: title, date, fovea, device, the
//! commands that measured, and what an incomplete run is missing; and the layers as the
//! reports name them.

use super::summary::Device;
use crate::foveation::FoveationConfig;
use std::fmt::Write as _;
use std::path::Path;

/// What heads every report: its title, when and by which fovea on which device it was
/// written, the commands that measured, and what is missing from an incomplete run.
pub struct ReportHead<'a> {
    pub title: &'a str,
    pub written_at: &'a str,
    pub fovea_version: &'a str,
    pub device: &'a Device,
    pub commands: &'a [String],
    /// `Some("N of M rows measured")` for an incomplete run.
    pub missing: Option<String>,
}

/// Writes the head of a report into `md`; `dir` is the run's directory, for `--resume`.
pub fn header(md: &mut String, head: &ReportHead, dir: &Path) {
    let d = head.device;
    let _ = writeln!(md, "# {}\n", head.title);
    let _ = writeln!(
        md,
        "Written {} by fovea {}. Device: **{}** ({}, driver {}, Vulkan {}).\n",
        head.written_at, head.fovea_version, d.name, d.kind, d.driver, d.api_version
    );
    for (i, command) in head.commands.iter().enumerate() {
        let what = if i == 0 { "Command" } else { "Resumed by" };
        let _ = writeln!(md, "{what}: `{command}`\n");
    }
    if let Some(missing) = &head.missing {
        let _ = writeln!(
            md,
            "**Incomplete run**: {missing}. Complete it with `fovea bench --resume {}`.\n",
            dir.display()
        );
    }
}

/// The layers as the reports name them: radius°/spacing, outermost "background/spacing".
pub fn layers_text(config: &FoveationConfig) -> String {
    config
        .layers
        .iter()
        .map(|l| match l.radius_deg {
            Some(r) => format!("{r}°/{}", l.spacing),
            None => format!("background/{}", l.spacing),
        })
        .collect::<Vec<_>>()
        .join(", ")
}
