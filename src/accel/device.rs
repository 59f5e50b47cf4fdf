//! The Embree device and its error callback, which turns Embree's errors into [`AccelError`]s, and
//! the Embree configuration ([`EmbreeConfig`]): the instruction set is the best one whose hits are
//! the same on every CPU that has it (AVX-512), else AVX2.

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
    isa: &'static str,
}

// SAFETY: Embree devices are thread-safe for the calls we make (scene creation and commit happen on
// one thread; queries on committed scenes are concurrent-safe per Embree's documentation).
unsafe impl Send for Device {}
// SAFETY: as above; the error sink is behind a Mutex.
unsafe impl Sync for Device {}

impl Device {
    /// Creates a device with the error callback installed, configured by [`EmbreeConfig::from_env`]
    /// (AVX-512 on a CPU with it, else AVX2, unless `$STRATA_EMBREE_CONFIG` pins one).
    pub fn new() -> Result<Self, AccelError> {
        Self::with_config(EmbreeConfig::from_env()?)
    }

    /// Creates a device from a parsed configuration, then asks Embree which instruction set it
    /// actually runs ([`Device::check_isa`]) and refuses one below AVX2 or other than `setup.isa`.
    pub fn with_config(setup: EmbreeConfig) -> Result<Self, AccelError> {
        let config = std::ffi::CString::new(setup.config)
            .map_err(|_| AccelError(format!("{CONFIG_VAR} contains a NUL byte")))?;
        // SAFETY: a NUL-terminated config string; a null return is checked.
        let raw = unsafe { sys::rtcNewDevice(config.as_ptr()) };
        if raw.is_null() {
            return Err(AccelError("rtcNewDevice failed (is libembree4 usable on this CPU?)".into()));
        }
        let sink = Box::new(ErrorSink(Mutex::new(Vec::new())));
        // SAFETY: `raw` is a live device; the sink pointer stays valid until after rtcReleaseDevice.
        unsafe { sys::rtcSetDeviceErrorFunction(raw, Some(error_callback), &*sink as *const ErrorSink as *mut c_void) };
        let device = Self { raw, sink, isa: setup.isa };
        device.check_isa()?;
        Ok(device)
    }

    /// Asks the running device for its packet widths (`rtcGetDeviceProperty`:
    /// `NATIVE_RAY8_SUPPORTED` is set when Embree enabled AVX or more, `NATIVE_RAY16_SUPPORTED`
    /// when it enabled AVX-512) and refuses a device below AVX (so below AVX2: strata's
    /// configuration never asks for plain AVX) or whose AVX-512 use differs from [`Device::isa`],
    /// the instruction set a render's identity records. This catches a configuration that reached
    /// Embree by a route [`EmbreeConfig::parse`] did not see.
    fn check_isa(&self) -> Result<(), AccelError> {
        // SAFETY: a live device; both properties are documented readable properties (an Embree
        // built without the width answers 0 or reports an error through the callback).
        let (ray8, ray16) = unsafe {
            (
                sys::rtcGetDeviceProperty(self.raw, sys::RTCDeviceProperty::NATIVE_RAY8_SUPPORTED),
                sys::rtcGetDeviceProperty(self.raw, sys::RTCDeviceProperty::NATIVE_RAY16_SUPPORTED),
            )
        };
        let _ = self.take_errors();
        let running = match (ray8 != 0, ray16 != 0) {
            (false, _) => "an instruction set below AVX (no 8-wide kernels)",
            (true, false) => "avx2",
            (true, true) => "avx512",
        };
        if running != self.isa {
            let why = if ray8 == 0 {
                "below AVX2, which strata needs (x86-64-v3)"
            } else {
                "not what the render's identity records"
            };
            return Err(AccelError(format!(
                "Embree runs {running} but strata configured isa={}: {why}; check {CONFIG_VAR}",
                self.isa
            )));
        }
        Ok(())
    }

    /// The instruction set Embree runs (`avx2` or `avx512`, as configured).
    pub fn isa(&self) -> &'static str {
        self.isa
    }

    /// The Embree library's version, e.g. `4.4.0` (part of a render's identity).
    pub fn version(&self) -> String {
        // SAFETY: a live device and a property every Embree 4 build answers.
        let v = unsafe { sys::rtcGetDeviceProperty(self.raw, sys::RTCDeviceProperty::VERSION) };
        format!("{}.{}.{}", v / 10000, v / 100 % 100, v % 100)
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

/// The environment variable with extra Embree configuration (`key=value`, comma-separated).
pub const CONFIG_VAR: &str = "STRATA_EMBREE_CONFIG";

/// The instruction set Embree runs by default on a CPU without AVX-512: every x86-64-v3 node (the
/// CPUs strata is built for) has it. On a CPU with AVX-512 the default is `avx512` instead
/// ([`default_isa`]): its kernels start reciprocals from `vrcp14ps`/`vrsqrt14ps`, which are
/// exactly specified, so every AVX-512 CPU reports the same hits, while AVX2 kernels' `vrcpps`
/// differs between CPU models (`accel/approx.rs`). The two kernels report different hits (907 of
/// 3072 pixel values of `hw4/cornellBRDF` differ): a cluster that mixes AVX-512 and AVX2-only
/// nodes pins `isa=avx2` on nodes of one CPU model (`docs/robustness.md`).
pub const DEFAULT_ISA: &str = "avx2";

/// The default instruction set on a CPU that has AVX-512 (`avx512`) or not ([`DEFAULT_ISA`]).
pub fn default_isa(avx512: bool) -> &'static str {
    if avx512 {
        "avx512"
    } else {
        DEFAULT_ISA
    }
}

/// Keys of `STRATA_EMBREE_CONFIG` that do not change which hits Embree reports (besides `isa` and
/// `max_isa`, which enter a render's identity through [`Device::isa`]).
const NEUTRAL_KEYS: [&str; 6] = ["verbose", "threads", "user_threads", "set_affinity", "start_threads", "hugepages"];

/// Embree instruction-set names below AVX2 (refused: strata needs AVX2, and Embree's SSE kernels
/// crashed in `rtcOccluded8` with the high-quality BVH).
const BELOW_AVX2: [&str; 9] = ["sse", "sse2", "sse3", "ssse3", "sse4.1", "sse41", "sse4.2", "sse42", "avx"];

/// The Embree configuration string of a device and the instruction set it selects.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct EmbreeConfig {
    /// `avx2` or `avx512`: what Embree runs
    pub isa: &'static str,
    /// the string given to `rtcNewDevice`
    pub config: String,
}

impl EmbreeConfig {
    /// [`EmbreeConfig::parse`] of `$STRATA_EMBREE_CONFIG` (unset: the defaults) on this CPU.
    pub fn from_env() -> Result<Self, AccelError> {
        let raw = std::env::var(CONFIG_VAR).ok();
        Self::parse(raw.as_deref().unwrap_or(""), cpu_has_avx512())
    }

    /// Parses `key=value` items of an Embree configuration, separated as Embree separates them
    /// (commas, spaces, tabs, newlines, carriage returns; keys and values are made of letters,
    /// digits, `_` and `.`, anything else is refused, so nothing can smuggle a second `isa` past
    /// this parser into Embree's):
    /// `isa` or `max_isa` (`avx2`, `avx512`; lower instruction sets are refused) and the keys that
    /// do not change hits (`verbose`, `threads`, ...); an unknown key is refused. The instruction
    /// set is [`default_isa`] (`avx512` on a CPU with AVX-512, `avx512` saying whether it has it,
    /// else `avx2`) unless `isa=avx2`/`max_isa=avx2` pins AVX2; `isa=avx512` is refused on a CPU
    /// without AVX-512, `max_isa=avx512` there gives `avx2`.
    pub fn parse(raw: &str, avx512: bool) -> Result<Self, AccelError> {
        let bad = |m: String| AccelError(format!("{CONFIG_VAR}={raw:?}: {m}"));
        let mut isa = default_isa(avx512);
        let mut isa_key: Option<&str> = None;
        let mut rest = Vec::new();
        let mut verbose = false;
        let word = |s: &str| !s.is_empty() && s.bytes().all(|b| b.is_ascii_alphanumeric() || b == b'_' || b == b'.');
        for item in raw.split([',', ' ', '\t', '\n', '\r']).filter(|s| !s.is_empty()) {
            let (key, value) = item.split_once('=').ok_or_else(|| bad(format!("`{item}`: expected key=value")))?;
            if !word(key) || !word(value) {
                return Err(bad(format!(
                    "`{}`: expected key=value made of letters, digits, `_` and `.`",
                    item.escape_debug()
                )));
            }
            match key {
                "isa" | "max_isa" => {
                    if let Some(k) = isa_key {
                        return Err(bad(format!("`{key}` after `{k}`: give the instruction set once")));
                    }
                    isa_key = Some(key);
                    let v = value.to_ascii_lowercase();
                    isa = match v.as_str() {
                        "avx2" => "avx2",
                        "avx512" | "avx512skx" => match (avx512, key) {
                            (true, _) => "avx512",
                            (false, "max_isa") => "avx2",
                            _ => return Err(bad("this CPU has no AVX-512 (AVX512F/CD/DQ/BW/VL)".into())),
                        },
                        v if BELOW_AVX2.contains(&v) => {
                            return Err(bad(format!(
                                "{key}={value} is below AVX2, which strata needs (x86-64-v3); use avx2 or avx512"
                            )))
                        }
                        _ => return Err(bad(format!("unknown instruction set `{value}` (avx2, avx512)"))),
                    };
                }
                k if NEUTRAL_KEYS.contains(&k) => {
                    verbose |= k == "verbose";
                    rest.push(format!("{key}={value}"));
                }
                _ => {
                    return Err(bad(format!(
                        "unknown key `{key}` (known: isa, max_isa, {}); keys that change the hits are not accepted",
                        NEUTRAL_KEYS.join(", ")
                    )))
                }
            }
        }
        let mut config = vec![format!("isa={isa}")];
        if !verbose {
            config.push("verbose=0".into());
        }
        config.extend(rest);
        Ok(Self { isa, config: config.join(",") })
    }
}

/// Whether this CPU has the AVX-512 subset Embree's `avx512` kernels use (SKX: F, CD, DQ, BW, VL).
pub fn cpu_has_avx512() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        std::arch::is_x86_feature_detected!("avx512f")
            && std::arch::is_x86_feature_detected!("avx512cd")
            && std::arch::is_x86_feature_detected!("avx512dq")
            && std::arch::is_x86_feature_detected!("avx512bw")
            && std::arch::is_x86_feature_detected!("avx512vl")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

#[cfg(test)]
mod config_tests {
    use super::EmbreeConfig;

    #[test]
    fn the_instruction_set_is_avx512_where_the_cpu_has_it_unless_avx2_is_pinned() {
        let c = EmbreeConfig::parse("", true).unwrap();
        assert_eq!((c.isa, c.config.as_str()), ("avx512", "isa=avx512,verbose=0"));
        let c = EmbreeConfig::parse("", false).unwrap();
        assert_eq!((c.isa, c.config.as_str()), ("avx2", "isa=avx2,verbose=0"));
        assert_eq!(EmbreeConfig::parse("isa=avx512", true).unwrap().isa, "avx512");
        assert_eq!(EmbreeConfig::parse("max_isa=avx512", true).unwrap().isa, "avx512");
        assert_eq!(EmbreeConfig::parse("max_isa=avx512", false).unwrap().isa, "avx2");
        assert_eq!(EmbreeConfig::parse("isa=avx2", true).unwrap().isa, "avx2");
        assert_eq!(EmbreeConfig::parse("max_isa=avx2", true).unwrap().isa, "avx2");
        let c = EmbreeConfig::parse("threads=2, verbose=1", true).unwrap();
        assert_eq!(c.config, "isa=avx512,threads=2,verbose=1");
        let c = EmbreeConfig::parse("threads=2, verbose=1", false).unwrap();
        assert_eq!(c.config, "isa=avx2,threads=2,verbose=1");
    }

    #[test]
    fn low_instruction_sets_unknown_keys_and_missing_avx512_are_refused() {
        for (raw, says) in [
            ("isa=sse2", "below AVX2"),
            ("isa=sse4.2", "below AVX2"),
            ("max_isa=avx", "below AVX2"),
            ("isa=neon", "unknown instruction set"),
            ("tri_accel=bvh4.triangle4v", "unknown key `tri_accel`"),
            ("isa", "expected key=value"),
            ("isa=avx2,max_isa=avx512", "give the instruction set once"),
            // Embree splits on newlines too: before, `threads=2\nisa=sse2` passed as one item.
            ("threads=2\nisa=sse2", "below AVX2"),
            ("threads=2\r\nisa=sse2", "below AVX2"),
            ("threads=2\x0bisa=sse2", "letters, digits"),
            ("threads=(2)", "letters, digits"),
            ("threads=2=isa=sse2", "letters, digits"),
        ] {
            let e = EmbreeConfig::parse(raw, true).unwrap_err().to_string();
            assert!(e.contains("STRATA_EMBREE_CONFIG") && e.contains(says), "{raw}: {e}");
        }
        let e = EmbreeConfig::parse("isa=avx512", false).unwrap_err().to_string();
        assert!(e.contains("no AVX-512"), "{e}");
    }

    /// A configuration that reaches Embree past the parser is caught by asking the running device.
    #[test]
    fn the_running_instruction_set_is_checked_against_the_identity() {
        let raw = |isa: &'static str, config: &str| EmbreeConfig { isa, config: format!("{config},verbose=0") };
        let e = super::Device::with_config(raw("avx2", "isa=sse2")).err().expect("sse2 refused").to_string();
        assert!(e.contains("below AVX2") && e.contains("isa=avx2"), "{e}");
        if super::cpu_has_avx512() {
            let e = super::Device::with_config(raw("avx2", "isa=avx512")).err().expect("refused").to_string();
            assert!(e.contains("runs avx512") && e.contains("identity"), "{e}");
            assert!(super::Device::with_config(raw("avx512", "isa=avx512")).is_ok());
        }
        let e = super::Device::with_config(raw("avx512", "isa=avx2")).err().expect("refused").to_string();
        assert!(e.contains("runs avx2") && e.contains("isa=avx512"), "{e}");
        assert!(super::Device::with_config(raw("avx2", "isa=avx2")).is_ok());
    }
}
