//! The FMI 2.0 C API of the tcsim converter models: Co-Simulation, with tcsim's BDF inside
//! `fmi2DoStep` (through `tcsim_core::stepper`), and Model Exchange, with the continuous states,
//! their derivatives, the event indicators of the stator clutch and of flow reversal, and the mode
//! switches in `fmi2NewDiscreteStates` (through `tcsim_core::engine::mode_view::ModeView`). No Python at
//! run time.
//!
//! The model and its parameters come from `resources/model.json`, written by `tcsim export-fmu`
//! (`python/tcsim/io/fmu.py`). The variables (value references, names, start values, states,
//! parameters, event indicators) are in one table, [`variables`], from which `tcsim export-fmu`
//! also writes `modelDescription.xml`. Every entry point catches panics: none crosses the C boundary; a
//! failure returns `fmi2Error` with its message through the logger callback.

// The `unsafe extern "C"` functions are the FMI 2.0 C API, called by the host with the pointers
// the standard defines; their safety contract is the FMI specification, not a per-function
// `# Safety` section.
#![allow(clippy::missing_safety_doc)]

pub mod fmi3;
mod instance;
mod snapshot;
pub mod uri;
pub mod variables;

use std::ffi::{c_char, c_int, c_void, CStr, CString};
use std::panic::{catch_unwind, AssertUnwindSafe};

use instance::Phase::{Initialization, Instantiated, Running, Terminated};
pub use instance::{Configuration, Instance, Phase};
pub use snapshot::Snapshot;
pub use variables::{FIRST_PARAMETER, MODEL_IDENTIFIER, SIGNALS};

type Status = c_int;
const OK: Status = 0;
const ERROR: Status = 3;
const FATAL: Status = 4;
const MODEL_EXCHANGE: c_int = 0;
const CO_SIMULATION: c_int = 1;

/// The log categories the library uses (declared in `<LogCategories>` of modelDescription.xml):
/// name and description.
pub const LOG_CATEGORIES: [(&str, &str); 2] = [
    ("logStatusError", "Calls that return fmi2Error, with the reason"),
    ("logStatusFatal", "Internal errors (a bug of the FMU), with the reason"),
];

type Logger = unsafe extern "C" fn(*mut c_void, *const c_char, Status, *const c_char, *const c_char, ...);

/// `fmi2CallbackFunctions`.
#[repr(C)]
#[derive(Clone, Copy)]
pub struct Callbacks {
    logger: Option<Logger>,
    allocate_memory: Option<unsafe extern "C" fn(usize, usize) -> *mut c_void>,
    free_memory: Option<unsafe extern "C" fn(*mut c_void)>,
    step_finished: Option<unsafe extern "C" fn(*mut c_void, Status)>,
    environment: *mut c_void,
}

/// What an `fmi2Component` points to.
pub struct Component {
    name: CString,
    callbacks: Option<Callbacks>,
    instance: Instance,
}

impl Component {
    fn log(&self, status: Status, message: &str) {
        let Some(cb) = self.callbacks else { return };
        let Some(logger) = cb.logger else { return };
        let msg = CString::new(message.replace('\0', " ")).unwrap_or_default();
        let category = if status >= FATAL { c"logStatusFatal" } else { c"logStatusError" };
        // the message is passed as an argument of "%s", so a '%' in it is not a format
        unsafe { logger(cb.environment, self.name.as_ptr(), status, category.as_ptr(), c"%s".as_ptr(), msg.as_ptr()) };
    }
}

/// The text of a caught panic (FMI 2.0 and 3.0 log it as an internal error).
pub(crate) fn panic_message(payload: Box<dyn std::any::Any + Send>) -> String {
    payload
        .downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| payload.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "unknown panic".into())
}

/// Run `f` on the component; an error or a panic is logged and becomes `fmi2Error`.
unsafe fn with(c: *mut c_void, f: impl FnOnce(&mut Component) -> Result<(), String>) -> Status {
    if c.is_null() {
        return ERROR;
    }
    let comp = unsafe { &mut *(c as *mut Component) };
    match catch_unwind(AssertUnwindSafe(|| f(comp))) {
        Ok(Ok(())) => OK,
        Ok(Err(msg)) => {
            comp.log(ERROR, &msg);
            ERROR
        }
        Err(payload) => {
            let msg = format!("internal error: {}", panic_message(payload));
            comp.log(FATAL, &msg);
            ERROR
        }
    }
}

/// The C array `p[..n]` (empty for n = 0; an error for a null pointer), for FMI 2.0 and 3.0.
pub(crate) unsafe fn slice<'a, T>(p: *const T, n: usize) -> Result<&'a [T], String> {
    if n == 0 {
        return Ok(&[]);
    }
    if p.is_null() {
        return Err("null array".into());
    }
    Ok(unsafe { std::slice::from_raw_parts(p, n) })
}

/// The C array `p[..n]`, writable (see [`slice`]).
pub(crate) unsafe fn slice_mut<'a, T>(p: *mut T, n: usize) -> Result<&'a mut [T], String> {
    if n == 0 {
        return Ok(&mut []);
    }
    if p.is_null() {
        return Err("null array".into());
    }
    Ok(unsafe { std::slice::from_raw_parts_mut(p, n) })
}

/// The GUID the FMU was exported with (`guid` of model.json; none in a hand-written one).
fn exported_guid(text: &str) -> Option<String> {
    let doc: serde_json::Value = serde_json::from_str(text).ok()?;
    doc.get("guid")?.as_str().map(str::to_string)
}

/// Check the instance's phase, and that it is of the interface (`Some(true)`: Model Exchange).
fn require(comp: &Component, call: &str, model_exchange: Option<bool>, allowed: &[Phase]) -> Result<(), String> {
    if let Some(me) = model_exchange.filter(|&me| me != comp.instance.model_exchange) {
        let (wanted, is) = if me { ("Model Exchange", "Co-Simulation") } else { ("Co-Simulation", "Model Exchange") };
        return Err(format!("{call} is a {wanted} function: this is a {is} instance"));
    }
    comp.instance.require(call, allowed)
}

#[no_mangle]
pub extern "C" fn fmi2GetTypesPlatform() -> *const c_char {
    c"default".as_ptr()
}

#[no_mangle]
pub extern "C" fn fmi2GetVersion() -> *const c_char {
    c"2.0".as_ptr()
}

#[no_mangle]
pub unsafe extern "C" fn fmi2SetDebugLogging(
    c: *mut c_void,
    _on: c_int,
    n: usize,
    categories: *const *const c_char,
) -> Status {
    unsafe {
        with(c, |_| {
            for &p in slice(categories, n)? {
                if p.is_null() {
                    return Err("null log category".into());
                }
                let name = CStr::from_ptr(p).to_string_lossy();
                if !LOG_CATEGORIES.iter().any(|(c, _)| *c == name) {
                    let known: Vec<&str> = LOG_CATEGORIES.iter().map(|c| c.0).collect();
                    return Err(format!("log category {name:?}: expected one of {}", known.join(", ")));
                }
            }
            Ok(())
        })
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi2Instantiate(
    name: *const c_char,
    kind: c_int,
    guid: *const c_char,
    resources: *const c_char,
    callbacks: *const Callbacks,
    _visible: c_int,
    _logging_on: c_int,
) -> *mut c_void {
    let result = catch_unwind(AssertUnwindSafe(|| {
        let name = if name.is_null() { CString::default() } else { unsafe { CStr::from_ptr(name) }.to_owned() };
        let callbacks = if callbacks.is_null() { None } else { Some(unsafe { *callbacks }) };
        let fail = |msg: String| {
            let comp = Component {
                name: name.clone(),
                callbacks,
                instance: Instance::new(Configuration {
                    causality: tcsim_core::engine::stepper::Causality::Speeds,
                    model: Default::default(),
                    parameters: vec![],
                }),
            };
            comp.log(ERROR, &msg);
            std::ptr::null_mut()
        };
        if kind != CO_SIMULATION && kind != MODEL_EXCHANGE {
            return fail(format!("fmuType {kind}: expected Model Exchange (0) or Co-Simulation (1)"));
        }
        if resources.is_null() {
            return fail("no fmuResourceLocation".into());
        }
        let dir = match uri::resources_path(&unsafe { CStr::from_ptr(resources) }.to_string_lossy()) {
            Ok(dir) => dir,
            Err(msg) => return fail(msg),
        };
        let text = match std::fs::read_to_string(format!("{dir}/model.json")) {
            Ok(t) => t,
            Err(e) => return fail(format!("{dir}/model.json: {e}")),
        };
        if let Some(expected) = exported_guid(&text) {
            let given = if guid.is_null() { None } else { Some(unsafe { CStr::from_ptr(guid) }.to_string_lossy()) };
            if given.as_deref() != Some(expected.as_str()) {
                return fail(format!(
                    "GUID {}: expected {expected} (the modelDescription.xml of this FMU)",
                    given.map_or_else(|| "null".to_string(), |g| format!("{g:?}"))
                ));
            }
        }
        match Configuration::parse(&text) {
            Ok(config) => {
                let mut instance = Instance::new(config);
                instance.model_exchange = kind == MODEL_EXCHANGE;
                Box::into_raw(Box::new(Component { name, callbacks, instance })) as *mut c_void
            }
            Err(msg) => fail(msg),
        }
    }));
    result.unwrap_or(std::ptr::null_mut())
}

#[no_mangle]
pub unsafe extern "C" fn fmi2FreeInstance(c: *mut c_void) {
    if !c.is_null() {
        let _ = catch_unwind(AssertUnwindSafe(|| drop(unsafe { Box::from_raw(c as *mut Component) })));
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi2SetupExperiment(
    c: *mut c_void,
    tolerance_defined: c_int,
    tolerance: f64,
    start: f64,
    _stop_defined: c_int,
    _stop: f64,
) -> Status {
    unsafe {
        with(c, |comp| {
            require(comp, "fmi2SetupExperiment", None, &[Instantiated])?;
            if !start.is_finite() {
                return Err(format!("fmi2SetupExperiment: startTime = {start}: expected a finite time"));
            }
            if tolerance_defined != 0 && tolerance.is_finite() && tolerance > 0.0 {
                comp.instance.options.rtol = tolerance.min(1e-4);
            }
            comp.instance.start_time = start;
            Ok(())
        })
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi2EnterInitializationMode(c: *mut c_void) -> Status {
    unsafe { with(c, |comp| comp.instance.enter_initialization()) }
}

#[no_mangle]
pub unsafe extern "C" fn fmi2ExitInitializationMode(c: *mut c_void) -> Status {
    unsafe { with(c, |comp| comp.instance.exit_initialization()) }
}

#[no_mangle]
pub unsafe extern "C" fn fmi2Terminate(c: *mut c_void) -> Status {
    unsafe { with(c, |comp| comp.instance.terminate()) }
}

#[no_mangle]
pub unsafe extern "C" fn fmi2Reset(c: *mut c_void) -> Status {
    unsafe {
        with(c, |comp| {
            comp.instance.reset();
            Ok(())
        })
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi2GetReal(c: *mut c_void, vr: *const u32, n: usize, values: *mut f64) -> Status {
    unsafe {
        with(c, |comp| {
            require(comp, "fmi2GetReal", None, &[Initialization, Running, Terminated])?;
            let (vr, values) = (slice(vr, n)?, slice_mut(values, n)?);
            for (r, v) in vr.iter().zip(values.iter_mut()) {
                *v = comp.instance.read(*r)?;
            }
            Ok(())
        })
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi2SetReal(c: *mut c_void, vr: *const u32, n: usize, values: *const f64) -> Status {
    unsafe { with(c, |comp| comp.instance.set_all(slice(vr, n)?, slice(values, n)?)) }
}

/// Integer, Boolean and String variables: the FMU has none.
unsafe fn none_of_type(c: *mut c_void, n: usize) -> Status {
    unsafe { with(c, |_| if n == 0 { Ok(()) } else { Err("this FMU has only Real variables".into()) }) }
}

#[no_mangle]
pub unsafe extern "C" fn fmi2GetInteger(c: *mut c_void, _vr: *const u32, n: usize, _v: *mut c_int) -> Status {
    unsafe { none_of_type(c, n) }
}

#[no_mangle]
pub unsafe extern "C" fn fmi2SetInteger(c: *mut c_void, _vr: *const u32, n: usize, _v: *const c_int) -> Status {
    unsafe { none_of_type(c, n) }
}

#[no_mangle]
pub unsafe extern "C" fn fmi2GetBoolean(c: *mut c_void, _vr: *const u32, n: usize, _v: *mut c_int) -> Status {
    unsafe { none_of_type(c, n) }
}

#[no_mangle]
pub unsafe extern "C" fn fmi2SetBoolean(c: *mut c_void, _vr: *const u32, n: usize, _v: *const c_int) -> Status {
    unsafe { none_of_type(c, n) }
}

#[no_mangle]
pub unsafe extern "C" fn fmi2GetString(c: *mut c_void, _vr: *const u32, n: usize, _v: *mut *const c_char) -> Status {
    unsafe { none_of_type(c, n) }
}

#[no_mangle]
pub unsafe extern "C" fn fmi2SetString(c: *mut c_void, _vr: *const u32, n: usize, _v: *const *const c_char) -> Status {
    unsafe { none_of_type(c, n) }
}

/// Capabilities the FMU declares it does not have.
unsafe fn unsupported(c: *mut c_void, what: &str) -> Status {
    unsafe { with(c, |_| Err(format!("{what} is not supported by this FMU"))) }
}

/// Store `snap` behind `*s`: a new FMU state, or over the one `*s` points to.
unsafe fn store(s: *mut *mut c_void, snap: Snapshot) -> Result<(), String> {
    if s.is_null() {
        return Err("null fmi2FMUstate pointer".into());
    }
    let existing = unsafe { *s } as *mut Snapshot;
    if existing.is_null() {
        unsafe { *s = Box::into_raw(Box::new(snap)) as *mut c_void };
    } else {
        let existing = unsafe { &mut *existing };
        existing.check_live()?;
        *existing = snap;
    }
    Ok(())
}

/// The FMU state behind `s`.
unsafe fn stored<'a>(s: *mut c_void) -> Result<&'a Snapshot, String> {
    if s.is_null() {
        return Err("null fmi2FMUstate".into());
    }
    let snap = unsafe { &*(s as *const Snapshot) };
    snap.check_live()?;
    Ok(snap)
}

#[no_mangle]
pub unsafe extern "C" fn fmi2GetFMUstate(c: *mut c_void, s: *mut *mut c_void) -> Status {
    unsafe { with(c, |comp| store(s, comp.instance.snapshot())) }
}

#[no_mangle]
pub unsafe extern "C" fn fmi2SetFMUstate(c: *mut c_void, s: *mut c_void) -> Status {
    unsafe { with(c, |comp| comp.instance.restore(stored(s)?)) }
}

#[no_mangle]
pub unsafe extern "C" fn fmi2FreeFMUstate(c: *mut c_void, s: *mut *mut c_void) -> Status {
    unsafe {
        with(c, |_| {
            if s.is_null() || (*s).is_null() {
                return Ok(());
            }
            stored(*s)?;
            let mut snap = Box::from_raw(*s as *mut Snapshot);
            snap.kill();
            drop(snap);
            *s = std::ptr::null_mut();
            Ok(())
        })
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi2SerializedFMUstateSize(c: *mut c_void, s: *mut c_void, n: *mut usize) -> Status {
    unsafe {
        with(c, |_| {
            let size = stored(s)?.to_bytes().len();
            if n.is_null() {
                return Err("null size pointer".into());
            }
            *n = size;
            Ok(())
        })
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi2SerializeFMUstate(c: *mut c_void, s: *mut c_void, b: *mut c_char, n: usize) -> Status {
    unsafe {
        with(c, |_| {
            let bytes = stored(s)?.to_bytes();
            if n < bytes.len() {
                return Err(format!("serialised FMU state of {} bytes: the buffer has {n}", bytes.len()));
            }
            slice_mut(b as *mut u8, bytes.len())?.copy_from_slice(&bytes);
            Ok(())
        })
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi2DeSerializeFMUstate(
    c: *mut c_void,
    b: *const c_char,
    n: usize,
    s: *mut *mut c_void,
) -> Status {
    unsafe {
        with(c, |comp| {
            let snap = Snapshot::from_bytes(slice(b as *const u8, n)?, &comp.instance)?;
            store(s, snap)
        })
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi2GetDirectionalDerivative(
    c: *mut c_void,
    _u: *const u32,
    _nu: usize,
    _z: *const u32,
    _nz: usize,
    _dv: *const f64,
    _dz: *mut f64,
) -> Status {
    unsafe { unsupported(c, "fmi2GetDirectionalDerivative") }
}

#[no_mangle]
pub unsafe extern "C" fn fmi2SetRealInputDerivatives(
    c: *mut c_void,
    vr: *const u32,
    n: usize,
    order: *const c_int,
    values: *const f64,
) -> Status {
    unsafe {
        with(c, |comp| {
            require(comp, "fmi2SetRealInputDerivatives", Some(false), &[Initialization, Running])?;
            for ((r, o), v) in slice(vr, n)?.iter().zip(slice(order, n)?).zip(slice(values, n)?) {
                comp.instance.set_rate(*r, *o, *v)?;
            }
            Ok(())
        })
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi2GetRealOutputDerivatives(
    c: *mut c_void,
    _vr: *const u32,
    _n: usize,
    _o: *const c_int,
    _v: *mut f64,
) -> Status {
    unsafe { unsupported(c, "fmi2GetRealOutputDerivatives") }
}

#[no_mangle]
pub unsafe extern "C" fn fmi2DoStep(c: *mut c_void, t: f64, h: f64, _no_prior_state: c_int) -> Status {
    unsafe { with(c, |comp| comp.instance.do_step(t, h)) }
}

#[no_mangle]
pub unsafe extern "C" fn fmi2CancelStep(c: *mut c_void) -> Status {
    unsafe { unsupported(c, "fmi2CancelStep (steps are synchronous)") }
}

#[no_mangle]
pub unsafe extern "C" fn fmi2GetStatus(c: *mut c_void, _kind: c_int, _value: *mut Status) -> Status {
    unsafe { unsupported(c, "fmi2GetStatus (steps are synchronous)") }
}

#[no_mangle]
pub unsafe extern "C" fn fmi2GetRealStatus(c: *mut c_void, _kind: c_int, _value: *mut f64) -> Status {
    unsafe { unsupported(c, "fmi2GetRealStatus") }
}

#[no_mangle]
pub unsafe extern "C" fn fmi2GetIntegerStatus(c: *mut c_void, _kind: c_int, _value: *mut c_int) -> Status {
    unsafe { unsupported(c, "fmi2GetIntegerStatus") }
}

#[no_mangle]
pub unsafe extern "C" fn fmi2GetBooleanStatus(c: *mut c_void, _kind: c_int, _value: *mut c_int) -> Status {
    unsafe { unsupported(c, "fmi2GetBooleanStatus") }
}

#[no_mangle]
pub unsafe extern "C" fn fmi2GetStringStatus(c: *mut c_void, _kind: c_int, _value: *mut *const c_char) -> Status {
    unsafe { unsupported(c, "fmi2GetStringStatus") }
}

// ---------------------------------------------------------------------------------------------
// Model Exchange

/// `fmi2EventInfo`.
#[repr(C)]
pub struct EventInfo {
    new_discrete_states_needed: c_int,
    terminate_simulation: c_int,
    nominals_of_continuous_states_changed: c_int,
    values_of_continuous_states_changed: c_int,
    next_event_time_defined: c_int,
    next_event_time: f64,
}

#[no_mangle]
pub unsafe extern "C" fn fmi2EnterEventMode(c: *mut c_void) -> Status {
    unsafe { with(c, |comp| require(comp, "fmi2EnterEventMode", Some(true), &[Running])) }
}

#[no_mangle]
pub unsafe extern "C" fn fmi2NewDiscreteStates(c: *mut c_void, info: *mut EventInfo) -> Status {
    unsafe {
        with(c, |comp| {
            require(comp, "fmi2NewDiscreteStates", Some(true), &[Running])?;
            let changed = comp.instance.me_new_discrete_states()?;
            if info.is_null() {
                return Err("null fmi2EventInfo".into());
            }
            let info = &mut *info;
            info.new_discrete_states_needed = 0;
            info.terminate_simulation = 0;
            info.nominals_of_continuous_states_changed = 0;
            info.values_of_continuous_states_changed = c_int::from(changed);
            info.next_event_time_defined = 0;
            info.next_event_time = 0.0;
            Ok(())
        })
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi2EnterContinuousTimeMode(c: *mut c_void) -> Status {
    unsafe { with(c, |comp| require(comp, "fmi2EnterContinuousTimeMode", Some(true), &[Running])) }
}

#[no_mangle]
pub unsafe extern "C" fn fmi2CompletedIntegratorStep(
    c: *mut c_void,
    _no_prior: c_int,
    enter_event_mode: *mut c_int,
    terminate: *mut c_int,
) -> Status {
    unsafe {
        with(c, |comp| {
            require(comp, "fmi2CompletedIntegratorStep", Some(true), &[Running])?;
            if !enter_event_mode.is_null() {
                *enter_event_mode = 0;
            }
            if !terminate.is_null() {
                *terminate = 0;
            }
            Ok(())
        })
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi2SetTime(c: *mut c_void, t: f64) -> Status {
    unsafe {
        with(c, |comp| {
            require(comp, "fmi2SetTime", Some(true), &[Running])?;
            comp.instance.me_set_time(t)
        })
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi2SetContinuousStates(c: *mut c_void, x: *const f64, n: usize) -> Status {
    unsafe {
        with(c, |comp| {
            require(comp, "fmi2SetContinuousStates", Some(true), &[Running])?;
            comp.instance.me_set_states(slice(x, n)?)
        })
    }
}

/// Check the host's array size against the model's.
fn sized(n: usize, expected: usize, what: &str) -> Result<(), String> {
    if n == expected {
        Ok(())
    } else {
        Err(format!("{n} {what} asked for, the model has {expected}"))
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi2GetContinuousStates(c: *mut c_void, x: *mut f64, n: usize) -> Status {
    unsafe {
        with(c, |comp| {
            require(comp, "fmi2GetContinuousStates", Some(true), &[Initialization, Running, Terminated])?;
            sized(n, comp.instance.me_sizes().0, "continuous states")?;
            comp.instance.provisional()?;
            comp.instance.me_get_states(slice_mut(x, n)?)
        })
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi2GetNominalsOfContinuousStates(c: *mut c_void, x: *mut f64, n: usize) -> Status {
    unsafe {
        with(c, |comp| {
            require(comp, "fmi2GetNominalsOfContinuousStates", Some(true), &Phase::ALL)?;
            sized(n, comp.instance.me_sizes().0, "continuous states")?;
            comp.instance.me_nominals(slice_mut(x, n)?)
        })
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi2GetDerivatives(c: *mut c_void, dx: *mut f64, n: usize) -> Status {
    unsafe {
        with(c, |comp| {
            require(comp, "fmi2GetDerivatives", Some(true), &[Initialization, Running, Terminated])?;
            sized(n, comp.instance.me_sizes().0, "derivatives")?;
            comp.instance.provisional()?;
            comp.instance.me_derivatives(slice_mut(dx, n)?)
        })
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi2GetEventIndicators(c: *mut c_void, g: *mut f64, n: usize) -> Status {
    unsafe {
        with(c, |comp| {
            require(comp, "fmi2GetEventIndicators", Some(true), &[Initialization, Running, Terminated])?;
            sized(n, comp.instance.me_sizes().1, "event indicators")?;
            comp.instance.provisional()?;
            comp.instance.me_indicators(slice_mut(g, n)?)
        })
    }
}
