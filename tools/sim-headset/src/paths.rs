//! Semantic paths (`xrStringToPath` / `xrPathToString`) and the spec's well-formedness rules.

use std::ffi::c_char;

use openxr_sys as xr;
use openxr_sys::Handle as _;

use crate::ffi::{self, XrResult};
use crate::registry::Runtime;

/// A well-formed path: starts with `/`, components of `[a-z0-9-_.]` that are not all dots,
/// no empty component, no trailing `/`, shorter than XR_MAX_PATH_LENGTH.
pub fn is_well_formed(s: &str) -> bool {
    if s.len() >= xr::MAX_PATH_LENGTH || !s.starts_with('/') {
        return false;
    }
    s[1..].split('/').all(|c| {
        !c.is_empty()
            && !c.chars().all(|ch| ch == '.')
            && c.chars()
                .all(|ch| ch.is_ascii_lowercase() || ch.is_ascii_digit() || "-_.".contains(ch))
    })
}

pub fn string_to_path(
    rt: &mut Runtime,
    instance: xr::Instance,
    s: *const c_char,
    out: *mut xr::Path,
) -> XrResult {
    rt.instance(instance)?;
    ffi::non_null(out)?;
    // SAFETY: the app passes a NUL-terminated string.
    let s = unsafe { ffi::read_cstr(s)? };
    if !is_well_formed(s) {
        return Err(xr::Result::ERROR_PATH_FORMAT_INVALID);
    }
    let path = rt.intern_path(instance.into_raw(), s)?;
    // SAFETY: checked non-null.
    unsafe { *out = path };
    Ok(xr::Result::SUCCESS)
}

pub fn path_to_string(
    rt: &Runtime,
    instance: xr::Instance,
    path: xr::Path,
    capacity: u32,
    count: *mut u32,
    buf: *mut c_char,
) -> XrResult {
    let s = rt.path_str(instance.into_raw(), path)?;
    // SAFETY: the app's buffer per the two-call idiom.
    unsafe { ffi::two_call_string(capacity, count, buf, s) }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn well_formed_paths() {
        for ok in [
            "/user/hand/left",
            "/interaction_profiles/khr/simple_controller",
            "/a.b-c_d/9",
        ] {
            assert!(is_well_formed(ok), "{ok}");
        }
        for bad in [
            "",
            "user",
            "/",
            "/user/",
            "/user//hand",
            "/User",
            "/a/..",
            "/a b",
            "/a/./b",
        ] {
            assert!(!is_well_formed(bad), "{bad}");
        }
    }
}
