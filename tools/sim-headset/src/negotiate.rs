//! The loader ↔ runtime handshake (`openxr_loader_negotiation.h`): the Khronos loader
//! finds the runtime through its manifest, calls this, and then uses the returned
//! `xrGetInstanceProcAddr` for everything else.

use openxr_sys as xr;

use crate::ffi::call;

/// The only loader/runtime interface version there is.
const RUNTIME_INTERFACE_VERSION: u32 = 1;

/// Exported from the cdylib for the OpenXR loader.
///
/// # Safety
/// The loader passes valid structures (null pointers are rejected).
#[no_mangle]
pub unsafe extern "system" fn xrNegotiateLoaderRuntimeInterface(
    loader_info: *const xr::NegotiateLoaderInfo,
    request: *mut xr::NegotiateRuntimeRequest,
) -> xr::Result {
    call("xrNegotiateLoaderRuntimeInterface", 0, || {
        if loader_info.is_null() || request.is_null() {
            return Err(xr::Result::ERROR_INITIALIZATION_FAILED);
        }
        // SAFETY: checked non-null; the loader owns both structures for the call.
        let (info, req) = unsafe { (&*loader_info, &mut *request) };
        let info_ok = info.struct_type == xr::NegotiateLoaderInfo::TYPE
            && info.struct_version == xr::NegotiateLoaderInfo::VERSION
            && info.struct_size == std::mem::size_of::<xr::NegotiateLoaderInfo>();
        let req_ok = req.struct_type == xr::NegotiateRuntimeRequest::TYPE
            && req.struct_version == xr::NegotiateRuntimeRequest::VERSION
            && req.struct_size == std::mem::size_of::<xr::NegotiateRuntimeRequest>();
        let version_ok = (info.min_interface_version..=info.max_interface_version)
            .contains(&RUNTIME_INTERFACE_VERSION)
            && info.min_api_version.major() <= 1
            && info.max_api_version.major() >= 1;
        if !(info_ok && req_ok && version_ok) {
            eprintln!("sim-headset: the OpenXR loader's negotiation request is not one this runtime understands");
            return Err(xr::Result::ERROR_INITIALIZATION_FAILED);
        }
        req.runtime_interface_version = RUNTIME_INTERFACE_VERSION;
        req.runtime_api_version = crate::API_VERSION;
        req.get_instance_proc_addr = Some(crate::dispatch::get_instance_proc_addr);
        Ok(xr::Result::SUCCESS)
    })
}
