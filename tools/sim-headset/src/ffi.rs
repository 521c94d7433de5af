//! The FFI boundary: panic containment, error bookkeeping, and the C idioms (structure
//! type checks, fixed-size strings, the two-call idiom, `next` chains).

use std::ffi::{c_char, c_void, CStr};
use std::panic::{catch_unwind, AssertUnwindSafe};

use openxr_sys as xr;

use crate::registry;

/// `Ok` carries the success code (XR_SUCCESS, XR_EVENT_UNAVAILABLE, ...), `Err` an error code.
pub type XrResult = Result<xr::Result, xr::Result>;

/// Runs one entry point: a panic becomes XR_ERROR_RUNTIME_FAILURE instead of unwinding into C
/// (undefined behaviour), and every error returned to the app is recorded against the
/// instance owning `handle` so the report can list it.
pub fn call(name: &'static str, handle: u64, f: impl FnOnce() -> XrResult) -> xr::Result {
    let result = match catch_unwind(AssertUnwindSafe(f)) {
        Ok(Ok(code)) | Ok(Err(code)) => code,
        Err(panic) => {
            let what = panic
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| panic.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "unknown panic".into());
            eprintln!("sim-headset: internal error in {name}: {what}");
            xr::Result::ERROR_RUNTIME_FAILURE
        }
    };
    // Loaders probe every function name they know, so an unsupported lookup is routine,
    // not an application error worth reporting.
    let probe = name == "xrGetInstanceProcAddr" && result == xr::Result::ERROR_FUNCTION_UNSUPPORTED;
    if result.into_raw() < 0 && !probe {
        registry::record_error(name, handle, result);
    }
    result
}

/// Null pointers the app must not pass are a validation failure, not a crash.
pub fn non_null<T>(p: *const T) -> Result<(), xr::Result> {
    if p.is_null() {
        Err(xr::Result::ERROR_VALIDATION_FAILURE)
    } else {
        Ok(())
    }
}

pub fn check_type(
    actual: xr::StructureType,
    expected: xr::StructureType,
) -> Result<(), xr::Result> {
    if actual == expected {
        Ok(())
    } else {
        Err(xr::Result::ERROR_VALIDATION_FAILURE)
    }
}

/// Copies `s` into a fixed-size C string field, truncating and always NUL-terminating.
pub fn write_fixed(dst: &mut [c_char], s: &str) {
    let n = s.len().min(dst.len() - 1);
    for (d, b) in dst.iter_mut().zip(s.bytes().take(n)) {
        *d = b as c_char;
    }
    dst[n] = 0;
}

/// Reads a fixed-size C string field; it must be NUL-terminated within the array.
pub fn read_fixed(src: &[c_char]) -> Option<String> {
    let end = src.iter().position(|&c| c == 0)?;
    let bytes: Vec<u8> = src[..end].iter().map(|&c| c as u8).collect();
    String::from_utf8(bytes).ok()
}

/// Reads a NUL-terminated string argument.
///
/// # Safety
/// `p` must be null or point to a NUL-terminated string that outlives the returned borrow.
pub unsafe fn read_cstr<'a>(p: *const c_char) -> Result<&'a str, xr::Result> {
    non_null(p)?;
    // SAFETY: non-null and NUL-terminated per the caller's contract.
    unsafe { CStr::from_ptr(p) }
        .to_str()
        .map_err(|_| xr::Result::ERROR_VALIDATION_FAILURE)
}

/// The two-call idiom: capacity 0 asks for the count; a smaller non-zero capacity is
/// XR_ERROR_SIZE_INSUFFICIENT (with the count still written); otherwise `write(i, slot)`
/// fills each element.
///
/// # Safety
/// `count_out` must be valid for writes; `buf` valid for `capacity` elements when capacity > 0.
pub unsafe fn two_call<T>(
    capacity: u32,
    count_out: *mut u32,
    buf: *mut T,
    len: usize,
    mut write: impl FnMut(usize, &mut T) -> Result<(), xr::Result>,
) -> XrResult {
    non_null(count_out)?;
    // SAFETY: checked non-null; valid for writes per the caller's contract.
    unsafe { *count_out = len as u32 };
    if capacity == 0 {
        return Ok(xr::Result::SUCCESS);
    }
    if (capacity as usize) < len {
        return Err(xr::Result::ERROR_SIZE_INSUFFICIENT);
    }
    non_null(buf)?;
    for i in 0..len {
        // SAFETY: i < len <= capacity, and the app provides `capacity` elements.
        write(i, unsafe { &mut *buf.add(i) })?;
    }
    Ok(xr::Result::SUCCESS)
}

/// The two-call idiom for a string (the count includes the terminating NUL).
///
/// # Safety
/// As for [`two_call`].
pub unsafe fn two_call_string(
    capacity: u32,
    count_out: *mut u32,
    buf: *mut c_char,
    s: &str,
) -> XrResult {
    let bytes: Vec<u8> = s.bytes().chain(std::iter::once(0)).collect();
    // SAFETY: forwarded contract.
    unsafe {
        two_call(capacity, count_out, buf, bytes.len(), |i, slot| {
            *slot = bytes[i] as c_char;
            Ok(())
        })
    }
}

/// Finds the structure of type `ty` in a `next` chain.
///
/// # Safety
/// `next` must be null or the head of a valid chain of OpenXR structures.
pub unsafe fn find_in_chain(next: *const c_void, ty: xr::StructureType) -> Option<*mut c_void> {
    let mut p = next as *const xr::BaseInStructure;
    while !p.is_null() {
        // SAFETY: every chained OpenXR structure starts with (type, next).
        let header = unsafe { &*p };
        if header.ty == ty {
            return Some(p as *mut c_void);
        }
        p = header.next;
    }
    None
}
