//! The C ABI of `include/flexdyn_client.h`: each function checks its pointers, runs the safe
//! [`crate::client`] call inside `catch_unwind` (no panic crosses into C), stores the error
//! message in the handle and returns the code.
//!
//! Every `unsafe` block here only turns a pointer the header documents into a reference or a
//! slice; the safety argument is the header's contract (valid, aligned, live for the call, and
//! `capacity` elements where a capacity is given), restated at each block.
#![allow(unsafe_code)]

use std::ffi::{c_char, c_int, CStr, CString};
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::PathBuf;
use std::time::Duration;

use flexdyn_proto::{CommandKind, Header, OperatorAction, MAX_ID_LEN};

use crate::client::{
    decode_imu_bytes, decode_star_tracker_bytes, decode_state_bytes, decode_status_bytes, Client,
    Kind, Options, Taken,
};
use crate::ctypes::{
    fill_state, FdEffectorInput, FdEffectorState, FdHeader, FdImuMsg, FdStarTrackerMsg, FdStateMsg,
    FdStatusMsg, FdTimeMsg,
};
use crate::error::{Code, Error};
use crate::from_c::{effector_input, finite3};
use crate::fsw::{self, FswStream};
use crate::kinds;

/// `flexdyn_client`: the opaque handle.
pub struct FlexdynClient {
    client: Option<Client>,
    last_error: CString,
    /// The bytes the last byte-level call handed out (valid until the next call).
    bytes: Vec<u8>,
}

/// `flexdyn_options`.
#[repr(C)]
pub struct FlexdynOptions {
    sc_id: *const c_char,
    connect: *const *const c_char,
    n_connect: usize,
    listen: *const *const c_char,
    n_listen: usize,
    zenoh_config_file: *const c_char,
}

impl FlexdynClient {
    fn set_error(&mut self, message: &str) {
        // A message never holds a NUL that would cut it short.
        self.last_error = CString::new(message.replace('\0', " ")).unwrap_or_default();
    }

    fn client(&mut self) -> Result<&mut Client, Error> {
        self.client.as_mut().ok_or_else(|| {
            Error::new(
                Code::Usage,
                "the session is not open (call flexdyn_open first)",
            )
        })
    }
}

/// What a panic carried, for the error message.
fn panic_message(payload: &(dyn std::any::Any + Send)) -> String {
    payload
        .downcast_ref::<&str>()
        .map(|s| (*s).to_owned())
        .or_else(|| payload.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "a panic without a message".to_owned())
}

/// Runs `f` on the handle: its error goes to `last_error`, a panic becomes
/// [`Code::Internal`]. A null handle is [`Code::Argument`] (there is nowhere to put a message).
fn with_handle(
    handle: *mut FlexdynClient,
    f: impl FnOnce(&mut FlexdynClient) -> Result<Code, Error>,
) -> c_int {
    with_handle_int(handle, |h| f(h).map(|code| code as c_int))
}

/// [`with_handle`] for a function that returns a plain value on success.
fn with_handle_int(
    handle: *mut FlexdynClient,
    f: impl FnOnce(&mut FlexdynClient) -> Result<c_int, Error>,
) -> c_int {
    // SAFETY: a non-null `handle` comes from `flexdyn_client_new` and is used by one thread at a
    // time (the header's threading contract), so a unique reference for this call is sound.
    let Some(h) = (unsafe { handle.as_mut() }) else {
        return Code::Argument as c_int;
    };
    match catch_unwind(AssertUnwindSafe(|| f(&mut *h))) {
        Ok(Ok(value)) => value,
        Ok(Err(e)) => {
            h.set_error(&e.message);
            e.code as c_int
        }
        Err(payload) => {
            h.set_error(&format!(
                "internal error (please report it; close this handle): {}",
                panic_message(payload.as_ref())
            ));
            Code::Internal as c_int
        }
    }
}

fn null(what: &str) -> Error {
    Error::new(Code::Argument, format!("{what} is a null pointer"))
}

/// A C string argument (`what` names it in errors).
///
/// # Safety
/// `p` is null or a NUL-terminated string live for the call.
unsafe fn c_str<'a>(what: &str, p: *const c_char) -> Result<&'a str, Error> {
    if p.is_null() {
        return Err(null(what));
    }
    // SAFETY: non-null and NUL-terminated, by this function's contract.
    unsafe { CStr::from_ptr(p) }
        .to_str()
        .map_err(|_| Error::new(Code::Argument, format!("{what} is not UTF-8")))
}

/// An optional C string argument: null is `None`.
///
/// # Safety
/// As [`c_str`].
unsafe fn opt_str<'a>(what: &str, p: *const c_char) -> Result<Option<&'a str>, Error> {
    if p.is_null() {
        Ok(None)
    } else {
        // SAFETY: forwarded contract.
        unsafe { c_str(what, p) }.map(Some)
    }
}

/// `n` C strings at `p` (null only when `n` is 0).
///
/// # Safety
/// `p` points to `n` NUL-terminated strings live for the call.
unsafe fn c_strs(what: &str, p: *const *const c_char, n: usize) -> Result<Vec<String>, Error> {
    if n == 0 {
        return Ok(Vec::new());
    }
    if p.is_null() {
        return Err(null(what));
    }
    // SAFETY: `n` pointers at `p`, by this function's contract.
    let ptrs = unsafe { std::slice::from_raw_parts(p, n) };
    ptrs.iter()
        .enumerate()
        // SAFETY: each entry is a NUL-terminated string, by this function's contract.
        .map(|(i, s)| unsafe { c_str(&format!("{what}[{i}]"), *s) }.map(str::to_owned))
        .collect()
}

/// Three doubles at `p`.
///
/// # Safety
/// `p` is null or points to 3 doubles.
unsafe fn vec3(what: &str, p: *const f64) -> Result<[f64; 3], Error> {
    if p.is_null() {
        return Err(null(what));
    }
    let mut v = [0.0; 3];
    // SAFETY: 3 doubles at `p`, by this function's contract.
    v.copy_from_slice(unsafe { std::slice::from_raw_parts(p, 3) });
    finite3(what, &v)?;
    Ok(v)
}

/// The Rust header of a C stamp.
///
/// # Safety
/// `p` is null or points to an `fd_header`.
unsafe fn stamp(p: *const FdHeader) -> Result<Header, Error> {
    // SAFETY: by this function's contract.
    let h = unsafe { p.as_ref() }.ok_or_else(|| null("stamp"))?;
    Ok(Header::new(h.spacecraft_id, h.tick, h.sim_time_ns, h.seq))
}

/// The Actuators command kind of C arguments.
///
/// # Safety
/// `torque` and `force` point to 3 doubles each; `inputs` to `n` `fd_effector_input`s (null
/// only when `n` is 0).
unsafe fn actuators(
    torque: *const f64,
    force: *const f64,
    inputs: *const FdEffectorInput,
    n: usize,
) -> Result<CommandKind, Error> {
    // SAFETY: forwarded contract.
    let (torque_b_nm, force_b_newton) =
        unsafe { (vec3("torque_b_nm", torque)?, vec3("force_b_newton", force)?) };
    let inputs = if n == 0 {
        Vec::new()
    } else if inputs.is_null() {
        return Err(null("inputs"));
    } else {
        // SAFETY: `n` inputs at `inputs`, by this function's contract.
        let c = unsafe { std::slice::from_raw_parts(inputs, n) };
        if n > flexdyn_proto::MAX_EFFECTORS {
            return Err(Error::new(
                Code::Argument,
                format!("{n} inputs exceed {}", flexdyn_proto::MAX_EFFECTORS),
            ));
        }
        c.iter()
            .enumerate()
            .map(|(i, x)| effector_input(i, x))
            .collect::<Result<_, _>>()?
    };
    Ok(CommandKind::Actuators {
        torque_b_nm,
        force_b_newton,
        inputs,
    })
}

/// The wrench command kind of C arguments.
///
/// # Safety
/// `torque` and `force` point to 3 doubles each.
unsafe fn wrench(torque: *const f64, force: *const f64) -> Result<CommandKind, Error> {
    // SAFETY: forwarded contract.
    unsafe {
        Ok(CommandKind::Wrench {
            torque_b_nm: vec3("torque_b_nm", torque)?,
            force_b_newton: vec3("force_b_newton", force)?,
        })
    }
}

/// Fills the caller's `fd_state_msg` from a decoded state.
///
/// # Safety
/// `out` is null or points to an `fd_state_msg` whose `effectors` points to
/// `effectors_capacity` entries (or is null with capacity 0).
unsafe fn write_state(out: *mut FdStateMsg, m: &flexdyn_proto::StateMsg) -> Result<(), Error> {
    // SAFETY: by this function's contract.
    let out = unsafe { out.as_mut() }.ok_or_else(|| null("out"))?;
    let effectors: &mut [FdEffectorState] = if out.effectors_capacity == 0 {
        &mut []
    } else if out.effectors.is_null() {
        return Err(null("out->effectors (with a capacity above 0)"));
    } else {
        // SAFETY: `effectors_capacity` entries at `effectors`, by this function's contract;
        // they lie outside `*out` (a separate array), so the two references do not overlap.
        unsafe { std::slice::from_raw_parts_mut(out.effectors, out.effectors_capacity) }
    };
    fill_state(m, out, effectors)
}

/// Writes `value` to `out`.
///
/// # Safety
/// `out` is null or points to a writable `T`.
unsafe fn write<T>(out: *mut T, value: T) -> Result<(), Error> {
    if out.is_null() {
        return Err(null("out"));
    }
    // SAFETY: non-null and writable, by this function's contract.
    unsafe { out.write(value) };
    Ok(())
}

/// The longest sensor name plus its NUL (`FLEXDYN_NAME_CAP` in the header).
const NAME_CAP: usize = MAX_ID_LEN + 1;

/// Checks a name buffer before a sample is taken (so a sample is never lost to it).
fn check_name_buffer(name_out: *mut c_char, name_cap: usize) -> Result<(), Error> {
    if !name_out.is_null() && name_cap < NAME_CAP {
        return Err(Error::new(
            Code::Argument,
            format!("name_cap is {name_cap}; a name needs up to {NAME_CAP} bytes"),
        ));
    }
    Ok(())
}

/// Copies `name` and its NUL into `name_out` (checked by [`check_name_buffer`]).
///
/// # Safety
/// `name_out` is null or points to `NAME_CAP` writable bytes.
unsafe fn write_name(name_out: *mut c_char, name: &str) {
    if name_out.is_null() {
        return;
    }
    let n = name.len().min(NAME_CAP - 1);
    // SAFETY: `NAME_CAP` writable bytes, by this function's contract; `n + 1 <= NAME_CAP`.
    unsafe {
        std::ptr::copy_nonoverlapping(name.as_ptr().cast::<c_char>(), name_out, n);
        *name_out.add(n) = 0;
    }
}

fn timeout(ms: u32) -> Duration {
    Duration::from_millis(u64::from(ms))
}

/// Takes the next sample of `kind` (poll when `wait` is `None`) and decodes it.
fn take<T>(
    h: &mut FlexdynClient,
    kind: Kind,
    wait: Option<u32>,
    decode_into: impl FnOnce(&str, &[u8]) -> Result<T, Error>,
) -> Result<Taken<(String, T)>, Error> {
    let client = h.client()?;
    let r = match client.receive(kind, wait.map(timeout))? {
        Taken::Got(r) => r,
        Taken::Empty => return Ok(Taken::Empty),
        Taken::Ended => return Ok(Taken::Ended),
    };
    let key = client.key_of(kind, &r.name);
    decode_into(&key, &r.payload).map(|m| Taken::Got((r.name, m)))
}

// ---------------------------------------------------------------------------------------------
// The handle.

/// `flexdyn_client_new`.
#[no_mangle]
pub extern "C" fn flexdyn_client_new() -> *mut FlexdynClient {
    catch_unwind(|| {
        Box::into_raw(Box::new(FlexdynClient {
            client: None,
            last_error: CString::default(),
            bytes: Vec::new(),
        }))
    })
    .unwrap_or(std::ptr::null_mut())
}

/// `flexdyn_client_free`.
///
/// # Safety
/// `handle` is null or from [`flexdyn_client_new`], not freed yet, and not used afterwards.
#[no_mangle]
pub unsafe extern "C" fn flexdyn_client_free(handle: *mut FlexdynClient) {
    if handle.is_null() {
        return;
    }
    // SAFETY: from `Box::into_raw` in `flexdyn_client_new`, freed once (this contract).
    let h = unsafe { Box::from_raw(handle) };
    let _ = catch_unwind(AssertUnwindSafe(move || {
        if let Some(c) = h.client {
            let _ = c.close();
        }
    }));
}

/// `flexdyn_last_error`.
///
/// # Safety
/// `handle` is null or a live handle.
#[no_mangle]
pub unsafe extern "C" fn flexdyn_last_error(handle: *const FlexdynClient) -> *const c_char {
    // SAFETY: a live handle, by this function's contract.
    match unsafe { handle.as_ref() } {
        Some(h) => h.last_error.as_ptr(),
        None => c"flexdyn_last_error: the handle is a null pointer".as_ptr(),
    }
}

/// `flexdyn_open`.
///
/// # Safety
/// `handle` is a live handle; `options` null or a valid `flexdyn_options` whose strings and
/// arrays are live for the call.
#[no_mangle]
pub unsafe extern "C" fn flexdyn_open(
    handle: *mut FlexdynClient,
    options: *const FlexdynOptions,
) -> c_int {
    with_handle(handle, |h| {
        if h.client.is_some() {
            return Err(Error::new(
                Code::Usage,
                "the session is open already (flexdyn_close it first)",
            ));
        }
        // SAFETY: by this function's contract.
        let opts = match unsafe { options.as_ref() } {
            None => Options::default(),
            // SAFETY: the strings and arrays of a valid `flexdyn_options`.
            Some(o) => unsafe {
                Options {
                    sc_id: opt_str("sc_id", o.sc_id)?.map(str::to_owned),
                    connect: c_strs("connect", o.connect, o.n_connect)?,
                    listen: c_strs("listen", o.listen, o.n_listen)?,
                    zenoh_config_file: opt_str("zenoh_config_file", o.zenoh_config_file)?
                        .map(PathBuf::from),
                }
            },
        };
        h.client = Some(Client::open(&opts)?);
        Ok(Code::Ok)
    })
}

/// `flexdyn_close`.
///
/// # Safety
/// `handle` is a live handle.
#[no_mangle]
pub unsafe extern "C" fn flexdyn_close(handle: *mut FlexdynClient) -> c_int {
    with_handle(handle, |h| {
        if let Some(c) = h.client.take() {
            c.close()?;
        }
        Ok(Code::Ok)
    })
}

/// `flexdyn_run_ended`: 1 (and the outputs filled) once the server's last status said the run
/// ended, 0 before (or when the session is not open), `FLEXDYN_ERR_ARGUMENT` for a null handle.
///
/// # Safety
/// `handle` is a live handle; `run_state_out` and `tick_out` null or writable.
#[no_mangle]
pub unsafe extern "C" fn flexdyn_run_ended(
    handle: *mut FlexdynClient,
    run_state_out: *mut i32,
    tick_out: *mut u64,
) -> c_int {
    with_handle_int(handle, |h| {
        let Some(end) = h.client.as_ref().and_then(Client::ended) else {
            return Ok(0);
        };
        if !run_state_out.is_null() {
            // The wire tag: 3, 4 or 5 (FD_RUN_STATE_FINISHED, _FAILED, _STOPPED).
            let tag = i32::try_from(end.run_state.tag()).unwrap_or(i32::MAX);
            // SAFETY: non-null and writable, by this function's contract.
            unsafe { run_state_out.write(tag) };
        }
        if !tick_out.is_null() {
            // SAFETY: non-null and writable, by this function's contract.
            unsafe { tick_out.write(end.tick) };
        }
        Ok(1)
    })
}

// ---------------------------------------------------------------------------------------------
// Subscriptions.

/// # Safety
/// `handle` is a live handle; `name` null or a NUL-terminated string.
unsafe fn subscribe(
    handle: *mut FlexdynClient,
    kind: Kind,
    name: *const c_char,
    capacity: usize,
) -> c_int {
    with_handle(handle, |h| {
        // SAFETY: forwarded contract.
        let name = unsafe { opt_str("name", name)? };
        h.client()?.subscribe(kind, name, capacity)?;
        Ok(Code::Ok)
    })
}

/// `FLEXDYN_OK` for a sample, `FLEXDYN_EMPTY` for none, `FLEXDYN_ENDED` after the run.
fn got<T>(r: &Taken<T>) -> Code {
    match r {
        Taken::Got(_) => Code::Ok,
        Taken::Empty => Code::Empty,
        Taken::Ended => Code::Ended,
    }
}

/// `flexdyn_subscribe_state`.
///
/// # Safety
/// `handle` is a live handle.
#[no_mangle]
pub unsafe extern "C" fn flexdyn_subscribe_state(
    handle: *mut FlexdynClient,
    capacity: usize,
) -> c_int {
    // SAFETY: forwarded contract.
    unsafe { subscribe(handle, kinds::STATE, std::ptr::null(), capacity) }
}

/// # Safety
/// As [`write_state`], and `handle` live.
unsafe fn state(handle: *mut FlexdynClient, out: *mut FdStateMsg, wait: Option<u32>) -> c_int {
    with_handle(handle, |h| {
        if out.is_null() {
            return Err(null("out"));
        }
        let r = take(h, kinds::STATE, wait, decode_state_bytes)?;
        if let Taken::Got((_, m)) = &r {
            // SAFETY: forwarded contract.
            unsafe { write_state(out, m)? };
        }
        Ok(got(&r))
    })
}

/// `flexdyn_poll_state`.
///
/// # Safety
/// `handle` is a live handle; `out` an `fd_state_msg` with `effectors_capacity` entries at
/// `effectors`.
#[no_mangle]
pub unsafe extern "C" fn flexdyn_poll_state(
    handle: *mut FlexdynClient,
    out: *mut FdStateMsg,
) -> c_int {
    // SAFETY: forwarded contract.
    unsafe { state(handle, out, None) }
}

/// `flexdyn_wait_state`.
///
/// # Safety
/// As [`flexdyn_poll_state`].
#[no_mangle]
pub unsafe extern "C" fn flexdyn_wait_state(
    handle: *mut FlexdynClient,
    out: *mut FdStateMsg,
    timeout_ms: u32,
) -> c_int {
    // SAFETY: forwarded contract.
    unsafe { state(handle, out, Some(timeout_ms)) }
}

fn imu_c(key: &str, b: &[u8]) -> Result<FdImuMsg, Error> {
    decode_imu_bytes(key, b).map(|m| FdImuMsg::from(&m))
}

fn star_tracker_c(key: &str, b: &[u8]) -> Result<FdStarTrackerMsg, Error> {
    decode_star_tracker_bytes(key, b).map(|m| FdStarTrackerMsg::from(&m))
}

fn time_c(key: &str, b: &[u8]) -> Result<FdTimeMsg, Error> {
    crate::client::decode_as("time", key, b, flexdyn_proto::decode_time)
        .map(|m| FdTimeMsg::from(&m))
}

fn status_c(key: &str, b: &[u8]) -> Result<FdStatusMsg, Error> {
    decode_status_bytes(key, b).map(|m| FdStatusMsg::from(&m))
}

/// `flexdyn_subscribe_time`.
///
/// # Safety
/// `handle` is a live handle.
#[no_mangle]
pub unsafe extern "C" fn flexdyn_subscribe_time(
    handle: *mut FlexdynClient,
    capacity: usize,
) -> c_int {
    // SAFETY: forwarded contract.
    unsafe { subscribe(handle, kinds::TIME, std::ptr::null(), capacity) }
}

/// A time message from `get` into `out` (`FLEXDYN_EMPTY` when there is none).
///
/// # Safety
/// `handle` live; `out` a writable `fd_time_msg`.
unsafe fn time_into(
    handle: *mut FlexdynClient,
    out: *mut FdTimeMsg,
    get: impl FnOnce(&mut Client) -> Result<Taken<flexdyn_proto::TimeMsg>, Error>,
) -> c_int {
    with_handle(handle, |h| {
        if out.is_null() {
            return Err(null("out"));
        }
        let m = get(h.client()?)?;
        let code = got(&m);
        if let Taken::Got(m) = m {
            // SAFETY: non-null and writable, by this function's contract.
            unsafe { write(out, FdTimeMsg::from(&m))? };
        }
        Ok(code)
    })
}

/// `flexdyn_wait_tick`: the next time message, waiting up to `timeout_ms`.
///
/// # Safety
/// `handle` live; `out` a writable `fd_time_msg`.
#[no_mangle]
pub unsafe extern "C" fn flexdyn_wait_tick(
    handle: *mut FlexdynClient,
    out: *mut FdTimeMsg,
    timeout_ms: u32,
) -> c_int {
    // SAFETY: forwarded contract.
    unsafe { time_into(handle, out, |c| c.take_time(Some(timeout(timeout_ms)))) }
}

/// `flexdyn_now`: the newest time message received (every queued one taken), no wait.
///
/// # Safety
/// `handle` live; `out` a writable `fd_time_msg`.
#[no_mangle]
pub unsafe extern "C" fn flexdyn_now(handle: *mut FlexdynClient, out: *mut FdTimeMsg) -> c_int {
    // SAFETY: forwarded contract.
    unsafe {
        time_into(handle, out, |c| {
            Ok(match c.now()? {
                Some(m) => Taken::Got(m),
                None => Taken::Empty,
            })
        })
    }
}

/// `flexdyn_send_operator`.
///
/// # Safety
/// `handle` live; `stamp` an `fd_header`.
#[no_mangle]
pub unsafe extern "C" fn flexdyn_send_operator(
    handle: *mut FlexdynClient,
    stamp: *const FdHeader,
    action: u32,
    ticks: u64,
) -> c_int {
    with_handle(handle, |h| {
        // SAFETY: forwarded contract.
        let stamp = unsafe { self::stamp(stamp)? };
        let action = match action {
            0 => OperatorAction::Pause,
            1 => OperatorAction::Resume,
            2 => OperatorAction::RunTicks,
            3 => OperatorAction::Checkpoint,
            other => {
                return Err(Error::new(
                    Code::Argument,
                    format!(
                        "operator action {other} is not FD_OPERATOR_PAUSE, _RESUME, _RUN_TICKS \
                         or _CHECKPOINT"
                    ),
                ))
            }
        };
        h.client()?.send_operator(&stamp, action, ticks)?;
        Ok(Code::Ok)
    })
}

// ---------------------------------------------------------------------------------------------
// Commands.

/// # Safety
/// `handle` live; `header` null or an `fd_header`.
unsafe fn send(
    handle: *mut FlexdynClient,
    sender_id: u32,
    header: *const FdHeader,
    kind: impl FnOnce() -> Result<CommandKind, Error>,
) -> c_int {
    with_handle(handle, |h| {
        // SAFETY: forwarded contract.
        let stamp = unsafe { stamp(header)? };
        let kind = kind()?;
        h.client()?.send(sender_id, &stamp, kind)?;
        Ok(Code::Ok)
    })
}

/// `flexdyn_send_wrench`.
///
/// # Safety
/// `handle` live; `stamp` an `fd_header`; `torque_b_nm` and `force_b_newton` 3 doubles each.
#[no_mangle]
pub unsafe extern "C" fn flexdyn_send_wrench(
    handle: *mut FlexdynClient,
    sender_id: u32,
    stamp: *const FdHeader,
    torque_b_nm: *const f64,
    force_b_newton: *const f64,
) -> c_int {
    // SAFETY: forwarded contract.
    unsafe {
        send(handle, sender_id, stamp, || {
            wrench(torque_b_nm, force_b_newton)
        })
    }
}

/// `flexdyn_send_no_command`.
///
/// # Safety
/// `handle` live; `stamp` an `fd_header`.
#[no_mangle]
pub unsafe extern "C" fn flexdyn_send_no_command(
    handle: *mut FlexdynClient,
    sender_id: u32,
    stamp: *const FdHeader,
) -> c_int {
    // SAFETY: forwarded contract.
    unsafe { send(handle, sender_id, stamp, || Ok(CommandKind::NoCommand)) }
}

/// `flexdyn_send_actuators`.
///
/// # Safety
/// As [`flexdyn_send_wrench`], and `inputs` `n_inputs` entries (null only when 0).
#[no_mangle]
pub unsafe extern "C" fn flexdyn_send_actuators(
    handle: *mut FlexdynClient,
    sender_id: u32,
    stamp: *const FdHeader,
    torque_b_nm: *const f64,
    force_b_newton: *const f64,
    inputs: *const FdEffectorInput,
    n_inputs: usize,
) -> c_int {
    // SAFETY: forwarded contract.
    unsafe {
        send(handle, sender_id, stamp, || {
            actuators(torque_b_nm, force_b_newton, inputs, n_inputs)
        })
    }
}

// ---------------------------------------------------------------------------------------------
// Lockstep.

/// `flexdyn_lockstep_join`.
///
/// # Safety
/// `handle` is a live handle.
#[no_mangle]
pub unsafe extern "C" fn flexdyn_lockstep_join(
    handle: *mut FlexdynClient,
    sender_id: u32,
    timeout_ms: u32,
) -> c_int {
    with_handle(handle, |h| {
        h.client()?.join(sender_id, timeout(timeout_ms))?;
        Ok(Code::Ok)
    })
}

/// `flexdyn_lockstep_wait`.
///
/// # Safety
/// As [`flexdyn_poll_state`].
#[no_mangle]
pub unsafe extern "C" fn flexdyn_lockstep_wait(
    handle: *mut FlexdynClient,
    state: *mut FdStateMsg,
    timeout_ms: u32,
) -> c_int {
    with_handle(handle, |h| {
        if state.is_null() {
            return Err(null("state"));
        }
        let Taken::Got(tick) = h.client()?.wait_tick(timeout(timeout_ms))? else {
            return Ok(Code::Ended);
        };
        // SAFETY: forwarded contract.
        unsafe { write_state(state, &tick.state)? };
        Ok(Code::Ok)
    })
}

/// `f` of the sensor names of the joined run (IMUs or star trackers; none before a join).
///
/// # Safety
/// `handle` null or live.
unsafe fn with_names<R>(
    handle: *const FlexdynClient,
    kind: Kind,
    f: impl FnOnce(&[CString]) -> R,
) -> R {
    // SAFETY: by this function's contract; read-only.
    let client = unsafe { handle.as_ref() }.and_then(|h| h.client.as_ref());
    f(client.map_or(&[][..], |c| c.sensor_names(kind)))
}

/// The pointer to name `index` (it lives in the handle until the next join, leave or close, as
/// the header says), null out of range.
fn name_ptr(names: &[CString], index: usize) -> *const c_char {
    names.get(index).map_or(std::ptr::null(), |n| n.as_ptr())
}

/// # Safety
/// `handle` live.
unsafe fn answer(
    handle: *mut FlexdynClient,
    kind: impl FnOnce() -> Result<CommandKind, Error>,
) -> c_int {
    with_handle(handle, |h| {
        let kind = kind()?;
        h.client()?.answer(kind)?;
        Ok(Code::Ok)
    })
}

/// `flexdyn_lockstep_answer_wrench`.
///
/// # Safety
/// `handle` live; `torque_b_nm` and `force_b_newton` 3 doubles each.
#[no_mangle]
pub unsafe extern "C" fn flexdyn_lockstep_answer_wrench(
    handle: *mut FlexdynClient,
    torque_b_nm: *const f64,
    force_b_newton: *const f64,
) -> c_int {
    // SAFETY: forwarded contract.
    unsafe { answer(handle, || wrench(torque_b_nm, force_b_newton)) }
}

/// `flexdyn_lockstep_answer_no_command`.
///
/// # Safety
/// `handle` live.
#[no_mangle]
pub unsafe extern "C" fn flexdyn_lockstep_answer_no_command(handle: *mut FlexdynClient) -> c_int {
    // SAFETY: forwarded contract.
    unsafe { answer(handle, || Ok(CommandKind::NoCommand)) }
}

/// `flexdyn_lockstep_answer_actuators`.
///
/// # Safety
/// As [`flexdyn_lockstep_answer_wrench`], and `inputs` `n_inputs` entries (null only when 0).
#[no_mangle]
pub unsafe extern "C" fn flexdyn_lockstep_answer_actuators(
    handle: *mut FlexdynClient,
    torque_b_nm: *const f64,
    force_b_newton: *const f64,
    inputs: *const FdEffectorInput,
    n_inputs: usize,
) -> c_int {
    // SAFETY: forwarded contract.
    unsafe {
        answer(handle, || {
            actuators(torque_b_nm, force_b_newton, inputs, n_inputs)
        })
    }
}

/// `flexdyn_lockstep_leave`.
///
/// # Safety
/// `handle` live.
#[no_mangle]
pub unsafe extern "C" fn flexdyn_lockstep_leave(handle: *mut FlexdynClient) -> c_int {
    with_handle(handle, |h| {
        h.client()?.leave();
        Ok(Code::Ok)
    })
}

// ---------------------------------------------------------------------------------------------
// Decoders.

/// The bytes `buf`/`len`.
///
/// # Safety
/// `buf` points to `len` bytes (null only when `len` is 0).
unsafe fn bytes<'a>(buf: *const u8, len: usize) -> Result<&'a [u8], Error> {
    if len == 0 {
        return Ok(&[]);
    }
    if buf.is_null() {
        return Err(null("buf"));
    }
    // SAFETY: by this function's contract.
    Ok(unsafe { std::slice::from_raw_parts(buf, len) })
}

/// `flexdyn_decode_state`.
///
/// # Safety
/// `handle` live; `buf` `len` bytes; `out` as in [`flexdyn_poll_state`].
#[no_mangle]
pub unsafe extern "C" fn flexdyn_decode_state(
    handle: *mut FlexdynClient,
    buf: *const u8,
    len: usize,
    out: *mut FdStateMsg,
) -> c_int {
    with_handle(handle, |_| {
        // SAFETY: forwarded contract.
        let m = decode_state_bytes("buf", unsafe { bytes(buf, len)? })?;
        // SAFETY: forwarded contract.
        unsafe { write_state(out, &m)? };
        Ok(Code::Ok)
    })
}

/// Decodes `buf` with `decode_into` and writes the result to `out`.
///
/// # Safety
/// `handle` live; `buf` `len` bytes; `out` a writable `T`.
unsafe fn decode_fixed<T>(
    handle: *mut FlexdynClient,
    buf: *const u8,
    len: usize,
    out: *mut T,
    decode_into: impl FnOnce(&str, &[u8]) -> Result<T, Error>,
) -> c_int {
    with_handle(handle, |_| {
        // SAFETY: forwarded contract.
        let m = decode_into("buf", unsafe { bytes(buf, len)? })?;
        // SAFETY: forwarded contract.
        unsafe { write(out, m)? };
        Ok(Code::Ok)
    })
}

/// `flexdyn_decode_imu`.
///
/// # Safety
/// `handle` live; `buf` `len` bytes; `out` a writable `fd_imu_msg`.
#[no_mangle]
pub unsafe extern "C" fn flexdyn_decode_imu(
    handle: *mut FlexdynClient,
    buf: *const u8,
    len: usize,
    out: *mut FdImuMsg,
) -> c_int {
    // SAFETY: forwarded contract.
    unsafe { decode_fixed(handle, buf, len, out, imu_c) }
}

/// `flexdyn_decode_star_tracker`.
///
/// # Safety
/// `handle` live; `buf` `len` bytes; `out` a writable `fd_star_tracker_msg`.
#[no_mangle]
pub unsafe extern "C" fn flexdyn_decode_star_tracker(
    handle: *mut FlexdynClient,
    buf: *const u8,
    len: usize,
    out: *mut FdStarTrackerMsg,
) -> c_int {
    // SAFETY: forwarded contract.
    unsafe { decode_fixed(handle, buf, len, out, star_tracker_c) }
}

/// `flexdyn_decode_time`.
///
/// # Safety
/// `handle` live; `buf` `len` bytes; `out` a writable `fd_time_msg`.
#[no_mangle]
pub unsafe extern "C" fn flexdyn_decode_time(
    handle: *mut FlexdynClient,
    buf: *const u8,
    len: usize,
    out: *mut FdTimeMsg,
) -> c_int {
    // SAFETY: forwarded contract.
    unsafe { decode_fixed(handle, buf, len, out, time_c) }
}

/// `flexdyn_decode_status`.
///
/// # Safety
/// `handle` live; `buf` `len` bytes; `out` a writable `fd_status_msg`.
#[no_mangle]
pub unsafe extern "C" fn flexdyn_decode_status(
    handle: *mut FlexdynClient,
    buf: *const u8,
    len: usize,
    out: *mut FdStatusMsg,
) -> c_int {
    // SAFETY: forwarded contract.
    unsafe { decode_fixed(handle, buf, len, out, status_c) }
}

// ---------------------------------------------------------------------------------------------
// The byte-level calls under the typed calls of `flexdyn_client_messages.h` (generated from the
// wire table): every message kind by its number.

/// A C `int` kind number as a [`Kind`] (a negative one is out of range, like a large one).
fn kind_of(kind: c_int) -> Result<Kind, Error> {
    let k = usize::try_from(kind).unwrap_or(usize::MAX);
    crate::client::check_kind(k).map(|_| k)
}

/// `flexdyn_subscribe_kind`.
///
/// # Safety
/// `handle` live; `name` null or a NUL-terminated string.
#[no_mangle]
pub unsafe extern "C" fn flexdyn_subscribe_kind(
    handle: *mut FlexdynClient,
    kind: c_int,
    name: *const c_char,
    capacity: usize,
) -> c_int {
    match kind_of(kind) {
        // SAFETY: forwarded contract.
        Ok(kind) => unsafe { subscribe(handle, kind, name, capacity) },
        Err(e) => with_handle(handle, |_| Err(e)),
    }
}

/// Keeps `data` in the handle and points `*bytes`/`*len` at it.
///
/// # Safety
/// `bytes` and `len` are writable (checked non-null by the caller).
unsafe fn hand_out(h: &mut FlexdynClient, data: Vec<u8>, bytes: *mut *const u8, len: *mut usize) {
    h.bytes = data;
    // SAFETY: writable, by this function's contract; the bytes live in the handle until the
    // next call on it (the header's contract).
    unsafe {
        bytes.write(h.bytes.as_ptr());
        len.write(h.bytes.len());
    }
}

/// Hands out the next checked sample of `kind`: its bytes stay in the handle until the next
/// call, `*bytes`/`*len` point at them.
///
/// # Safety
/// `handle` live; `bytes` and `len` writable; `name_out` null or `name_cap` writable bytes.
unsafe fn take_bytes(
    handle: *mut FlexdynClient,
    kind: c_int,
    bytes: *mut *const u8,
    len: *mut usize,
    name_out: *mut c_char,
    name_cap: usize,
    wait: Option<u32>,
) -> c_int {
    with_handle(handle, |h| {
        let kind = kind_of(kind)?;
        if bytes.is_null() || len.is_null() {
            return Err(null("bytes or len"));
        }
        check_name_buffer(name_out, name_cap)?;
        let r = match h.client()?.receive_checked(kind, wait.map(timeout))? {
            Taken::Got(r) => r,
            Taken::Empty => return Ok(Code::Empty),
            Taken::Ended => return Ok(Code::Ended),
        };
        // SAFETY: `bytes`, `len` writable and `name_cap >= NAME_CAP` (checked), by this
        // function's contract.
        unsafe {
            hand_out(h, r.payload, bytes, len);
            write_name(name_out, &r.name);
        }
        Ok(Code::Ok)
    })
}

/// `flexdyn_poll_bytes`.
///
/// # Safety
/// As [`take_bytes`].
#[no_mangle]
pub unsafe extern "C" fn flexdyn_poll_bytes(
    handle: *mut FlexdynClient,
    kind: c_int,
    bytes: *mut *const u8,
    len: *mut usize,
    name_out: *mut c_char,
    name_cap: usize,
) -> c_int {
    // SAFETY: forwarded contract.
    unsafe { take_bytes(handle, kind, bytes, len, name_out, name_cap, None) }
}

/// `flexdyn_wait_bytes`.
///
/// # Safety
/// As [`take_bytes`].
#[no_mangle]
pub unsafe extern "C" fn flexdyn_wait_bytes(
    handle: *mut FlexdynClient,
    kind: c_int,
    bytes: *mut *const u8,
    len: *mut usize,
    name_out: *mut c_char,
    name_cap: usize,
    timeout_ms: u32,
) -> c_int {
    // SAFETY: forwarded contract.
    unsafe {
        take_bytes(
            handle,
            kind,
            bytes,
            len,
            name_out,
            name_cap,
            Some(timeout_ms),
        )
    }
}

/// `flexdyn_publish_bytes`.
///
/// # Safety
/// `handle` live; `buf` `len` bytes.
#[no_mangle]
pub unsafe extern "C" fn flexdyn_publish_bytes(
    handle: *mut FlexdynClient,
    kind: c_int,
    buf: *const u8,
    len: usize,
) -> c_int {
    with_handle(handle, |h| {
        let kind = kind_of(kind)?;
        // SAFETY: forwarded contract.
        let b = unsafe { bytes(buf, len)? };
        h.client()?.publish(kind, b)?;
        Ok(Code::Ok)
    })
}

/// `flexdyn_lockstep_sensor_count`.
///
/// # Safety
/// `handle` null or live.
#[no_mangle]
pub unsafe extern "C" fn flexdyn_lockstep_sensor_count(
    handle: *const FlexdynClient,
    kind: c_int,
) -> usize {
    let Ok(kind) = kind_of(kind) else { return 0 };
    // SAFETY: forwarded contract.
    catch_unwind(AssertUnwindSafe(|| unsafe {
        with_names(handle, kind, <[CString]>::len)
    }))
    .unwrap_or(0)
}

/// `flexdyn_lockstep_sensor_name`: null for an index out of range.
///
/// # Safety
/// `handle` null or live.
#[no_mangle]
pub unsafe extern "C" fn flexdyn_lockstep_sensor_name(
    handle: *const FlexdynClient,
    kind: c_int,
    index: usize,
) -> *const c_char {
    let Ok(kind) = kind_of(kind) else {
        return std::ptr::null();
    };
    // SAFETY: forwarded contract.
    catch_unwind(AssertUnwindSafe(|| unsafe {
        with_names(handle, kind, |n| name_ptr(n, index))
    }))
    .unwrap_or(std::ptr::null())
}

/// `flexdyn_lockstep_sample_bytes`.
///
/// # Safety
/// `handle` live; `bytes` and `len` writable.
#[no_mangle]
pub unsafe extern "C" fn flexdyn_lockstep_sample_bytes(
    handle: *mut FlexdynClient,
    kind: c_int,
    index: usize,
    bytes: *mut *const u8,
    len: *mut usize,
) -> c_int {
    with_handle(handle, |h| {
        let kind = kind_of(kind)?;
        if bytes.is_null() || len.is_null() {
            return Err(null("bytes or len"));
        }
        let sample = h.client()?.held_sample(kind, index)?;
        // SAFETY: `bytes` and `len` writable (checked non-null), by this function's contract.
        unsafe { hand_out(h, sample, bytes, len) };
        Ok(Code::Ok)
    })
}

/// `flexdyn_decode_failed`: the C decoder refused bytes the library handed out.
///
/// # Safety
/// `handle` live; `field` null or a NUL-terminated string.
#[no_mangle]
pub unsafe extern "C" fn flexdyn_decode_failed(
    handle: *mut FlexdynClient,
    kind: c_int,
    fd_status: c_int,
    field: *const c_char,
) -> c_int {
    with_handle(handle, |_| {
        let kind = kind_of(kind)?;
        let info = &kinds::KINDS[kind];
        // SAFETY: forwarded contract; a field name is ASCII.
        let field = unsafe { opt_str("field", field)? }.unwrap_or("");
        // FD_ERR_CAPACITY (7): the caller's array is too small.
        if fd_status == 7 {
            return Err(Error::new(
                Code::Capacity,
                format!(
                    "a {} sample does not fit your array ({field}); the sample is dropped",
                    info.title
                ),
            ));
        }
        Err(Error::new(
            Code::Decode,
            format!(
                "an undecodable {} sample (fd_status {fd_status}, {field}): flexdyn_proto.h \
                 refused what the Rust codec accepted; please report it",
                info.title
            ),
        ))
    })
}

/// `flexdyn_fail`: records `message` as the handle's last error and returns `code`.
///
/// # Safety
/// `handle` live; `message` null or a NUL-terminated string.
#[no_mangle]
pub unsafe extern "C" fn flexdyn_fail(
    handle: *mut FlexdynClient,
    code: c_int,
    message: *const c_char,
) -> c_int {
    with_handle_int(handle, |h| {
        // SAFETY: forwarded contract.
        let m = unsafe { opt_str("message", message)? }.unwrap_or("");
        h.set_error(m);
        Ok(code)
    })
}

/// `flexdyn_struct_size`.
#[no_mangle]
pub extern "C" fn flexdyn_struct_size(which: c_int) -> usize {
    use std::mem::size_of;
    match which {
        0 => size_of::<FdHeader>(),
        1 => size_of::<FdStateMsg>(),
        2 => size_of::<FdEffectorState>(),
        3 => size_of::<FdImuMsg>(),
        4 => size_of::<FdStarTrackerMsg>(),
        5 => size_of::<FdEffectorInput>(),
        6 => size_of::<FdStatusMsg>(),
        7 => size_of::<FdTimeMsg>(),
        _ => 0,
    }
}

// ---------------------------------------------------------------------------------------------
// The flight code's own telemetry streams (FswMsg, protocol 10).

/// `flexdyn_fsw_stream`: a declared stream, its sample being filled in and its publisher.
pub struct FlexdynFswStream {
    stream: FswStream,
    last_error: CString,
}

/// Runs `f` on the stream handle, as [`with_handle_int`] does on a client handle: its error
/// goes to the stream's `last_error`, a panic becomes [`Code::Internal`], a null handle is
/// [`Code::Argument`].
fn with_stream(
    handle: *mut FlexdynFswStream,
    f: impl FnOnce(&mut FswStream) -> Result<(), Error>,
) -> c_int {
    // SAFETY: a non-null `handle` comes from `flexdyn_fsw_declare` and is used by one thread at
    // a time (the header's threading contract), so a unique reference for this call is sound.
    let Some(h) = (unsafe { handle.as_mut() }) else {
        return Code::Argument as c_int;
    };
    match catch_unwind(AssertUnwindSafe(|| f(&mut h.stream))) {
        Ok(Ok(())) => Code::Ok as c_int,
        Ok(Err(e)) => {
            h.last_error = CString::new(e.message.replace('\0', " ")).unwrap_or_default();
            e.code as c_int
        }
        Err(payload) => {
            h.last_error = CString::new(
                format!(
                    "internal error (please report it; free this stream): {}",
                    panic_message(payload.as_ref())
                )
                .replace('\0', " "),
            )
            .unwrap_or_default();
            Code::Internal as c_int
        }
    }
}

/// `n` doubles at `p`, for `what`.
///
/// # Safety
/// `p` is null or points to `N` doubles.
unsafe fn doubles<const N: usize>(what: &str, p: *const f64) -> Result<[f64; N], Error> {
    if p.is_null() {
        return Err(null(what));
    }
    let mut v = [0.0; N];
    // SAFETY: `N` doubles at `p`, by this function's contract.
    v.copy_from_slice(unsafe { std::slice::from_raw_parts(p, N) });
    Ok(v)
}

/// `n` elements at `p` (null only when `n` is 0).
///
/// # Safety
/// `p` points to `n` `T`s live for the call.
unsafe fn elements<'a, T>(p: *const T, n: usize) -> Result<&'a [T], Error> {
    if n == 0 {
        return Ok(&[]);
    }
    if p.is_null() {
        return Err(null("v"));
    }
    // SAFETY: `n` elements at `p`, by this function's contract.
    Ok(unsafe { std::slice::from_raw_parts(p, n) })
}

/// `flexdyn_fsw_declare`.
///
/// # Safety
/// `handle` live; `stream` a NUL-terminated string; `out` null or writable.
#[no_mangle]
pub unsafe extern "C" fn flexdyn_fsw_declare(
    handle: *mut FlexdynClient,
    stream: *const c_char,
    out: *mut *mut FlexdynFswStream,
    timeout_ms: u32,
) -> c_int {
    if !out.is_null() {
        // SAFETY: non-null and writable, by this function's contract.
        unsafe { out.write(std::ptr::null_mut()) };
    }
    with_handle(handle, |h| {
        if out.is_null() {
            return Err(null("out"));
        }
        // SAFETY: forwarded contract.
        let name = unsafe { c_str("stream", stream)? };
        let stream = h.client()?.declare_fsw(name, timeout(timeout_ms))?;
        let boxed = Box::into_raw(Box::new(FlexdynFswStream {
            stream,
            last_error: CString::default(),
        }));
        // SAFETY: non-null and writable (checked), by this function's contract.
        unsafe { out.write(boxed) };
        Ok(Code::Ok)
    })
}

/// `flexdyn_fsw_free`.
///
/// # Safety
/// `handle` null or from [`flexdyn_fsw_declare`], not freed yet, and not used afterwards.
#[no_mangle]
pub unsafe extern "C" fn flexdyn_fsw_free(handle: *mut FlexdynFswStream) {
    if handle.is_null() {
        return;
    }
    // SAFETY: from `Box::into_raw` in `flexdyn_fsw_declare`, freed once (this contract).
    let h = unsafe { Box::from_raw(handle) };
    let _ = catch_unwind(AssertUnwindSafe(move || drop(h)));
}

/// `flexdyn_fsw_last_error`.
///
/// # Safety
/// `handle` is null or a live stream.
#[no_mangle]
pub unsafe extern "C" fn flexdyn_fsw_last_error(handle: *const FlexdynFswStream) -> *const c_char {
    // SAFETY: a live stream, by this function's contract.
    match unsafe { handle.as_ref() } {
        Some(h) => h.last_error.as_ptr(),
        None => c"flexdyn_fsw_last_error: the stream is a null pointer".as_ptr(),
    }
}

/// `flexdyn_fsw_begin`.
///
/// # Safety
/// `handle` live; `stamp` null or an `fd_header`.
#[no_mangle]
pub unsafe extern "C" fn flexdyn_fsw_begin(
    handle: *mut FlexdynFswStream,
    stamp: *const FdHeader,
) -> c_int {
    with_stream(handle, |s| {
        // SAFETY: forwarded contract.
        let stamp = unsafe { self::stamp(stamp)? };
        Ok(s.begin_stamped(&stamp)?)
    })
}

/// `flexdyn_fsw_set_mode`.
///
/// # Safety
/// `handle` live; `mode` null or a NUL-terminated string.
#[no_mangle]
pub unsafe extern "C" fn flexdyn_fsw_set_mode(
    handle: *mut FlexdynFswStream,
    mode: *const c_char,
) -> c_int {
    with_stream(handle, |s| {
        // SAFETY: forwarded contract.
        let mode = unsafe { c_str("mode", mode)? };
        Ok(s.mode(mode)?)
    })
}

/// `flexdyn_fsw_add_event`.
///
/// # Safety
/// `handle` live; `event` null or a NUL-terminated string.
#[no_mangle]
pub unsafe extern "C" fn flexdyn_fsw_add_event(
    handle: *mut FlexdynFswStream,
    event: *const c_char,
) -> c_int {
    with_stream(handle, |s| {
        // SAFETY: forwarded contract.
        let event = unsafe { c_str("event", event)? };
        Ok(s.event(event)?)
    })
}

/// `flexdyn_fsw_set_estimate`.
///
/// # Safety
/// `handle` live; `q_bn` null or 4 doubles.
#[no_mangle]
pub unsafe extern "C" fn flexdyn_fsw_set_estimate(
    handle: *mut FlexdynFswStream,
    q_bn: *const f64,
) -> c_int {
    with_stream(handle, |s| {
        // SAFETY: forwarded contract.
        let q = unsafe { doubles::<4>("q_bn", q_bn)? };
        Ok(s.estimate(q)?)
    })
}

/// `flexdyn_fsw_set_target`.
///
/// # Safety
/// `handle` live; `q_rn` null or 4 doubles.
#[no_mangle]
pub unsafe extern "C" fn flexdyn_fsw_set_target(
    handle: *mut FlexdynFswStream,
    q_rn: *const f64,
) -> c_int {
    with_stream(handle, |s| {
        // SAFETY: forwarded contract.
        let q = unsafe { doubles::<4>("q_rn", q_rn)? };
        Ok(s.target(q)?)
    })
}

/// `flexdyn_fsw_set_variance`.
///
/// # Safety
/// `handle` live; `var_b_rad2` null or 3 doubles.
#[no_mangle]
pub unsafe extern "C" fn flexdyn_fsw_set_variance(
    handle: *mut FlexdynFswStream,
    var_b_rad2: *const f64,
) -> c_int {
    with_stream(handle, |s| {
        // SAFETY: forwarded contract.
        let v = unsafe { doubles::<3>("var_b_rad2", var_b_rad2)? };
        Ok(s.variance(v)?)
    })
}

/// Sets value `name` of the sample begun from `n` elements at `v` with `set`.
///
/// # Safety
/// `handle` live; `name` null or a NUL-terminated string; `v` `n` elements (null only when 0).
unsafe fn set_value<T>(
    handle: *mut FlexdynFswStream,
    name: *const c_char,
    v: *const T,
    n: usize,
    set: impl FnOnce(&mut FswStream, &str, &[T]) -> Result<(), fsw::FswError>,
) -> c_int {
    with_stream(handle, |s| {
        // SAFETY: forwarded contract.
        let (name, v) = unsafe { (c_str("name", name)?, elements(v, n)?) };
        Ok(set(s, name, v)?)
    })
}

/// `flexdyn_fsw_set_f64`.
///
/// # Safety
/// `handle` live; `name` a NUL-terminated string; `v` `n` doubles (null only when 0).
#[no_mangle]
pub unsafe extern "C" fn flexdyn_fsw_set_f64(
    handle: *mut FlexdynFswStream,
    name: *const c_char,
    v: *const f64,
    n: usize,
) -> c_int {
    // SAFETY: forwarded contract.
    unsafe { set_value(handle, name, v, n, |s, name, v| s.f64s(name, v)) }
}

/// `flexdyn_fsw_set_i64`.
///
/// # Safety
/// `handle` live; `name` a NUL-terminated string; `v` `n` `int64_t`s (null only when 0).
#[no_mangle]
pub unsafe extern "C" fn flexdyn_fsw_set_i64(
    handle: *mut FlexdynFswStream,
    name: *const c_char,
    v: *const i64,
    n: usize,
) -> c_int {
    // SAFETY: forwarded contract.
    unsafe { set_value(handle, name, v, n, |s, name, v| s.i64s(name, v)) }
}

/// `flexdyn_fsw_set_bool`.
///
/// # Safety
/// `handle` live; `name` a NUL-terminated string; `v` `n` `int`s (null only when 0).
#[no_mangle]
pub unsafe extern "C" fn flexdyn_fsw_set_bool(
    handle: *mut FlexdynFswStream,
    name: *const c_char,
    v: *const c_int,
    n: usize,
) -> c_int {
    // SAFETY: forwarded contract.
    unsafe { set_value(handle, name, v, n, |s, name, v| fsw::set_bools(s, name, v)) }
}

/// `flexdyn_fsw_publish`.
///
/// # Safety
/// `handle` live.
#[no_mangle]
pub unsafe extern "C" fn flexdyn_fsw_publish(handle: *mut FlexdynFswStream) -> c_int {
    with_stream(handle, |s| Ok(s.publish()?))
}
