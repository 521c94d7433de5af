//! The frame loop: xrWaitFrame / xrBeginFrame / xrEndFrame, their order rules, layer
//! validation, state advancement and saving submitted eye images.

use std::path::Path;

use openxr_sys as xr;
use openxr_sys::Handle as _;

use crate::ffi::{self, XrResult};
use crate::readback;
use crate::registry::Runtime;
use crate::session::{self, with_both};
use crate::system::MAX_LAYERS;

use crate::clock::FRAME_PERIOD_NS;

pub fn wait_frame(
    rt: &mut Runtime,
    session: xr::Session,
    info: *const xr::FrameWaitInfo,
    state: &mut xr::FrameState,
) -> XrResult {
    rt.live_session(session)?;
    if !info.is_null() {
        // SAFETY: non-null, the app's input structure.
        ffi::check_type(unsafe { (*info).ty }, xr::StructureType::FRAME_WAIT_INFO)?;
    }
    ffi::check_type(state.ty, xr::StructureType::FRAME_STATE)?;
    with_both(rt, session, |inst, s, id| {
        if !s.running {
            return Err(xr::Result::ERROR_SESSION_NOT_RUNNING);
        }
        let frame = s.frames.waits;
        s.frames.waits += 1;
        s.frames.wait_pending = true;
        inst.log.frames_waited += 1;
        state.predicted_display_time = xr::Time::from_nanos(s.frames.clock.wait_frame());
        state.predicted_display_period = xr::Duration::from_nanos(FRAME_PERIOD_NS);
        let losses_left = inst
            .config
            .losses
            .is_none_or(|n| inst.log.sessions_lost < n);
        if inst.config.loss_at_frame == Some(frame) && losses_left {
            inst.log.sessions_lost += 1;
            session::lose(inst, s, id);
            state.should_render = xr::FALSE;
            return Ok(xr::Result::SESSION_LOSS_PENDING);
        }
        if s.state == xr::SessionState::READY {
            session::transition(inst, s, id, xr::SessionState::SYNCHRONIZED);
        }
        if inst.config.exit_at_frame == Some(frame) && !s.exit_requested {
            session::stop(inst, s, id);
        }
        let visible = matches!(
            s.state,
            xr::SessionState::VISIBLE | xr::SessionState::FOCUSED
        );
        let wanted = !inst
            .config
            .no_render
            .is_some_and(|(from, to)| (from..=to).contains(&frame));
        state.should_render = (visible && wanted).into();
        Ok(xr::Result::SUCCESS)
    })
}

pub fn begin_frame(
    rt: &mut Runtime,
    session: xr::Session,
    info: *const xr::FrameBeginInfo,
) -> XrResult {
    rt.live_session(session)?;
    if !info.is_null() {
        // SAFETY: non-null, the app's input structure.
        ffi::check_type(unsafe { (*info).ty }, xr::StructureType::FRAME_BEGIN_INFO)?;
    }
    with_both(rt, session, |_, s, _| {
        if !s.running {
            return Err(xr::Result::ERROR_SESSION_NOT_RUNNING);
        }
        if !s.frames.wait_pending {
            return Err(xr::Result::ERROR_CALL_ORDER_INVALID);
        }
        s.frames.wait_pending = false;
        if s.frames.frame_begun {
            // The previous frame was begun but never ended: it is discarded.
            return Ok(xr::Result::FRAME_DISCARDED);
        }
        s.frames.frame_begun = true;
        Ok(xr::Result::SUCCESS)
    })
}

/// The (swapchain, image index, array layer, rect) of each eye of a projection layer.
type EyeImage = (u64, u32, u32, xr::Rect2Di);

fn check_sub_image(
    rt: &Runtime,
    session: u64,
    sub: &xr::SwapchainSubImage,
) -> Result<EyeImage, xr::Result> {
    let sc = rt.swapchain(sub.swapchain)?;
    if sc.session != session {
        return Err(xr::Result::ERROR_HANDLE_INVALID);
    }
    let released = sc.last_released.ok_or(xr::Result::ERROR_LAYER_INVALID)?;
    let r = sub.image_rect;
    let inside = r.offset.x >= 0
        && r.offset.y >= 0
        && r.extent.width > 0
        && r.extent.height > 0
        && r.offset.x as i64 + r.extent.width as i64 <= sc.width as i64
        && r.offset.y as i64 + r.extent.height as i64 <= sc.height as i64;
    if !inside {
        return Err(xr::Result::ERROR_SWAPCHAIN_RECT_INVALID);
    }
    if sub.image_array_index >= sc.array_size {
        return Err(xr::Result::ERROR_VALIDATION_FAILURE);
    }
    Ok((sub.swapchain.into_raw(), released, sub.image_array_index, r))
}

fn check_space(rt: &Runtime, session: u64, space: xr::Space) -> Result<(), xr::Result> {
    if rt.space(space)?.session != session {
        return Err(xr::Result::ERROR_HANDLE_INVALID);
    }
    Ok(())
}

/// Validates the submitted layers; returns the eye images of the first projection layer.
fn check_layers(
    rt: &Runtime,
    session: u64,
    info: &xr::FrameEndInfo,
) -> Result<Option<[EyeImage; 2]>, xr::Result> {
    if info.layer_count > MAX_LAYERS {
        return Err(xr::Result::ERROR_LAYER_LIMIT_EXCEEDED);
    }
    if info.layer_count > 0 {
        ffi::non_null(info.layers)?;
    }
    let mut eyes = None;
    for k in 0..info.layer_count as usize {
        // SAFETY: `layers` holds `layer_count` pointers (checked non-null above).
        let layer = unsafe { *info.layers.add(k) };
        if layer.is_null() {
            return Err(xr::Result::ERROR_LAYER_INVALID);
        }
        // SAFETY: non-null layer; every layer starts with the base header.
        let ty = unsafe { (*layer).ty };
        match ty {
            xr::StructureType::COMPOSITION_LAYER_PROJECTION => {
                // SAFETY: the header's type says this is a projection layer.
                let p = unsafe { &*(layer as *const xr::CompositionLayerProjection) };
                check_space(rt, session, p.space)?;
                if p.view_count != 2 || p.views.is_null() {
                    return Err(xr::Result::ERROR_VALIDATION_FAILURE);
                }
                // SAFETY: `views` holds `view_count` (= 2) structures.
                let views = unsafe { std::slice::from_raw_parts(p.views, 2) };
                let mut found = Vec::with_capacity(2);
                for v in views {
                    ffi::check_type(v.ty, xr::StructureType::COMPOSITION_LAYER_PROJECTION_VIEW)?;
                    if !crate::pose::is_valid(&v.pose) {
                        return Err(xr::Result::ERROR_POSE_INVALID);
                    }
                    found.push(check_sub_image(rt, session, &v.sub_image)?);
                }
                if eyes.is_none() {
                    eyes = Some([found[0], found[1]]);
                }
            }
            xr::StructureType::COMPOSITION_LAYER_QUAD => {
                // SAFETY: the header's type says this is a quad layer.
                let q = unsafe { &*(layer as *const xr::CompositionLayerQuad) };
                check_space(rt, session, q.space)?;
                check_sub_image(rt, session, &q.sub_image)?;
            }
            _ => return Err(xr::Result::ERROR_LAYER_INVALID),
        }
    }
    Ok(eyes)
}

fn save_eyes(
    rt: &Runtime,
    session: xr::Session,
    dir: &Path,
    frame: u64,
    eyes: &[EyeImage; 2],
) -> Result<(), String> {
    std::fs::create_dir_all(dir).map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
    let s = rt.session(session).map_err(|e| format!("{e:?}"))?;
    for (eye, &(swapchain, index, layer, rect)) in eyes.iter().enumerate() {
        let sc = &rt.swapchains[&swapchain];
        let image = sc.images.images[index as usize];
        let texels = readback::read_rect(&s.vk, image, sc.format, layer, rect)
            .map_err(|e| format!("reading the eye {eye} image back failed: {e:?}"))?;
        let rgb = readback::to_rgb8(sc.format, &texels);
        let path = dir.join(format!("frame-{frame:04}-eye-{eye}.png"));
        readback::write_png(
            &path,
            rect.extent.width as u32,
            rect.extent.height as u32,
            &rgb,
        )
        .map_err(|e| format!("cannot write {}: {e}", path.display()))?;
    }
    Ok(())
}

pub fn end_frame(rt: &mut Runtime, session: xr::Session, info: &xr::FrameEndInfo) -> XrResult {
    let s = rt.live_session(session)?;
    ffi::check_type(info.ty, xr::StructureType::FRAME_END_INFO)?;
    if !s.running {
        return Err(xr::Result::ERROR_SESSION_NOT_RUNNING);
    }
    if !s.frames.frame_begun {
        return Err(xr::Result::ERROR_CALL_ORDER_INVALID);
    }
    if info.display_time.as_nanos() <= 0 {
        return Err(xr::Result::ERROR_TIME_INVALID);
    }
    if info.environment_blend_mode != xr::EnvironmentBlendMode::OPAQUE {
        return Err(xr::Result::ERROR_ENVIRONMENT_BLEND_MODE_UNSUPPORTED);
    }
    let eyes = check_layers(rt, session.into_raw(), info)?;
    let frame = s.frames.waits.saturating_sub(1);
    let save_dir = rt.instances[&s.instance].config.save_dir.clone();
    let mut saved = false;
    if let (Some(dir), Some(eyes)) = (save_dir, eyes) {
        if let Err(message) = save_eyes(rt, session, &dir, frame, &eyes) {
            eprintln!("sim-headset: frame {frame}: {message}");
            return Err(xr::Result::ERROR_RUNTIME_FAILURE);
        }
        saved = true;
    }
    with_both(rt, session, |inst, s, id| {
        s.frames.frame_begun = false;
        inst.log.frames_submitted += 1;
        inst.log.frames_with_layers += (info.layer_count > 0) as u64;
        if saved {
            inst.log.images_saved += 2;
        }
        // Submitted frames bring the session into view, then into focus.
        if !s.exit_requested {
            match s.state {
                xr::SessionState::SYNCHRONIZED => {
                    session::transition(inst, s, id, xr::SessionState::VISIBLE)
                }
                xr::SessionState::VISIBLE => {
                    session::transition(inst, s, id, xr::SessionState::FOCUSED)
                }
                _ => {}
            }
        }
        Ok(xr::Result::SUCCESS)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_period_is_90_hz() {
        assert_eq!(FRAME_PERIOD_NS, 11_111_111);
    }
}
