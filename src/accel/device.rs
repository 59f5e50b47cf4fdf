//! The Embree device and its error callback, which turns Embree's errors into [`AccelError`]s.

use embree4_sys as sys;
use std::ffi::{c_char, c_void, CStr};
use std::sync::Mutex;

/// Errors from Embree, with its message.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("Embree: {0}")]
pub struct AccelError(pub String);

/// Collects messages from Embree's error callback.
struct ErrorSink(Mutex<Vec<String>>);

unsafe extern "C" fn error_callback(user: *mut c_void, code: sys::RTCError, msg: *const c_char) {
    // SAFETY: `user` is the `ErrorSink` boxed in `Device`, which outlives the device handle
    // (released in Device::drop before the box); `msg` is NUL-terminated or null per Embree's API.
    let (sink, text) = unsafe {
        let sink = &*(user as *const ErrorSink);
        let text = if msg.is_null() { String::new() } else { CStr::from_ptr(msg).to_string_lossy().into_owned() };
        (sink, text)
    };
    if let Ok(mut v) = sink.0.lock() {
        v.push(format!("{code:?}: {text}"));
    }
}

/// An Embree device with an error callback that turns errors into Rust errors.
pub struct Device {
    pub(super) raw: sys::RTCDevice,
    sink: Box<ErrorSink>,
}

// SAFETY: Embree devices are thread-safe for the calls we make (scene creation and commit happen on
// one thread; queries on committed scenes are concurrent-safe per Embree's documentation).
unsafe impl Send for Device {}
// SAFETY: as above; the error sink is behind a Mutex.
unsafe impl Sync for Device {}

impl Device {
    /// Creates a device with the error callback installed. The Embree configuration string is
    /// `verbose=0`, or `$STRATA_EMBREE_CONFIG` when set (e.g. `isa=avx2`).
    pub fn new() -> Result<Self, AccelError> {
        let config = std::env::var("STRATA_EMBREE_CONFIG").unwrap_or_else(|_| "verbose=0".into());
        let config = std::ffi::CString::new(config)
            .map_err(|_| AccelError("STRATA_EMBREE_CONFIG contains a NUL byte".into()))?;
        // SAFETY: a NUL-terminated config string; a null return is checked.
        let raw = unsafe { sys::rtcNewDevice(config.as_ptr()) };
        if raw.is_null() {
            return Err(AccelError("rtcNewDevice failed (is libembree4 usable on this CPU?)".into()));
        }
        let sink = Box::new(ErrorSink(Mutex::new(Vec::new())));
        // SAFETY: `raw` is a live device; the sink pointer stays valid until after rtcReleaseDevice.
        unsafe { sys::rtcSetDeviceErrorFunction(raw, Some(error_callback), &*sink as *const ErrorSink as *mut c_void) };
        Ok(Self { raw, sink })
    }

    /// Whether this Embree build has point geometry (`RTC_GEOMETRY_TYPE_SPHERE_POINT`, used by
    /// [`super::SceneBuilder::add_spheres`]).
    pub fn supports_points(&self) -> bool {
        // SAFETY: a live device and a property every Embree 4 build answers.
        let v = unsafe { sys::rtcGetDeviceProperty(self.raw, sys::RTCDeviceProperty::POINT_GEOMETRY_SUPPORTED) };
        v != 0
    }

    /// Returns (and clears) the errors Embree reported since the last call.
    pub fn take_errors(&self) -> Result<(), AccelError> {
        let mut v = self.sink.0.lock().map_err(|_| AccelError("error sink poisoned".into()))?;
        if v.is_empty() {
            Ok(())
        } else {
            Err(AccelError(std::mem::take(&mut *v).join("; ")))
        }
    }
}

impl Drop for Device {
    fn drop(&mut self) {
        // SAFETY: the device was created by rtcNewDevice and is released once; all scenes hold
        // their own reference so releasing here is safe even if a Scene outlives this handle.
        unsafe { sys::rtcReleaseDevice(self.raw) };
    }
}
