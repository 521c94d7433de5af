//! One frame's eyes: the views the runtime located at the predicted display time, the scene
//! cameras they become, the images fovea renders for them, and the lens's visibility mask of
//! each image.

use super::error::{XrContext, XrError};
use super::poses::SpacePlacement;
use super::swapchains::EyeSwapchain;
use crate::foveation::{Gaze, ImageGeometry, VisibilityMask};
use crate::render::EyeView;
use crate::scene::Camera;
use openxr as xr;

/// The view configuration fovea renders: two eyes.
pub(super) const VIEW_TYPE: xr::ViewConfigurationType = xr::ViewConfigurationType::PRIMARY_STEREO;

/// Where the eyes are for the frame displayed at `time`.
pub(super) struct EyeViews {
    pub(super) time: xr::Time,
    /// The runtime's views (pose and field of view), for the composition layer.
    pub(super) located: Vec<xr::View>,
    pub(super) cameras: Vec<Camera>,
    /// The eyes as the renderer is asked for them; their gaze is latched later.
    pub(super) eyes: Vec<EyeView>,
    pub(super) images: Vec<ImageGeometry>,
    /// Each eye's image size.
    pub(super) size: [u32; 2],
}

impl EyeViews {
    /// Locates the eyes in `space` at `time` and places them in the scene.
    pub(super) fn locate(
        session: &xr::Session<xr::Vulkan>,
        space: &xr::Space,
        placement: &SpacePlacement,
        time: xr::Time,
        size: [u32; 2],
    ) -> Result<Self, XrError> {
        let (_, located) = session
            .locate_views(VIEW_TYPE, time, space)
            .xr("xrLocateViews")?;
        let cameras: Vec<Camera> = located
            .iter()
            .map(|v| placement.eye_camera(&v.pose, &v.fov))
            .collect();
        let eyes: Vec<EyeView> = cameras
            .iter()
            .map(|c| EyeView {
                camera: *c,
                gaze: Gaze::Forward,
            })
            .collect();
        let images = eyes.iter().map(|e| e.image(size[0], size[1])).collect();
        Ok(Self {
            time,
            located,
            cameras,
            eyes,
            images,
            size,
        })
    }

    /// The predicted display time in seconds (the runtime's clock).
    pub(super) fn time_s(&self) -> f64 {
        self.time.as_nanos() as f64 * 1e-9
    }

    /// Each eye's view of the projection layer: its pose and field of view, and its
    /// swapchain's image.
    pub(super) fn projection_views<'a>(
        &self,
        swapchains: &'a [EyeSwapchain],
    ) -> Vec<xr::CompositionLayerProjectionView<'a, xr::Vulkan>> {
        self.located
            .iter()
            .zip(swapchains)
            .map(|(view, swapchain)| {
                xr::CompositionLayerProjectionView::new()
                    .pose(view.pose)
                    .fov(view.fov)
                    .sub_image(swapchain.sub_image())
            })
            .collect()
    }
}

/// Each eye's visibility mask from the runtime's hidden-triangle meshes.
pub(super) fn visibility_masks(
    session: &xr::Session<xr::Vulkan>,
    images: &[ImageGeometry],
) -> Result<Vec<VisibilityMask>, XrError> {
    images
        .iter()
        .enumerate()
        .map(|(e, image)| {
            let mesh = session
                .get_visibility_mask_khr(
                    VIEW_TYPE,
                    e as u32,
                    xr::VisibilityMaskTypeKHR::HIDDEN_TRIANGLE_MESH,
                )
                .xr("xrGetVisibilityMaskKHR")?;
            let vertices: Vec<[f32; 2]> = mesh.vertices.iter().map(|v| [v.x, v.y]).collect();
            let mask = VisibilityMask::from_hidden_triangles(image, &vertices, &mesh.indices);
            tracing::info!(
                "eye {e}: the lens shows {} of {} pixels",
                mask.visible_count(),
                image.width * image.height
            );
            Ok(mask)
        })
        .collect()
}
