//! The C API's parameters: `sc_params_new`, then a sequence of `sc_params_set_int`,
//! `_double`, `_bool` and `sc_params_get_*` calls with any option name (a known one, or any
//! bytes), value, NULL handle or name; and the option table's queries with any index.
//! Never `SC_STATUS_PANIC`; a value set reads back unchanged; every option stays within
//! `[sc_option_min, sc_option_max]`.
//!
//! Input: repeated `op: u8, name, value`. `op % 6` picks the call, `op & 0x40` a NULL name,
//! `op & 0x80` a NULL handle. A name is a byte `k`: below 0xE0 option `k % sc_option_count()`
//! (or the index just past the end, NULL), else that many bytes (NULs dropped).
#![no_main]

use std::ffi::{c_char, CStr, CString};
use std::ptr::{null, null_mut};

use libfuzzer_sys::fuzz_target;
use shapecorr::ffi::*;
use shapecorr_fuzz::Bytes;

fn name(b: &mut Bytes) -> CString {
    let k = b.u8();
    let count = sc_option_count();
    if k < 0xE0 {
        let p = sc_option_name(k as usize % (count + 1));
        // SAFETY: a static NUL-terminated string (or NULL past the end).
        return if p.is_null() {
            CString::default()
        } else {
            unsafe { CStr::from_ptr(p) }.into()
        };
    }
    let bytes: Vec<u8> = b.bytes(64).iter().copied().filter(|&c| c != 0).collect();
    CString::new(bytes).expect("NULs dropped")
}

fn int(b: &mut Bytes) -> i64 {
    match b.u8() % 4 {
        0 => b.u8() as i8 as i64,
        1 => [i64::MIN, i64::MAX, -1, 0][b.u8() as usize % 4],
        _ => b.u64() as i64,
    }
}

fn double(b: &mut Bytes) -> f64 {
    match b.u8() % 4 {
        0 => f64::from(b.u8() as i8) / 16.0,
        1 => [
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
            -0.0,
            f64::MIN_POSITIVE,
            f64::MAX,
        ][b.u8() as usize % 6],
        _ => b.f64(),
    }
}

/// Every option holds a value of its type within its range.
unsafe fn check_ranges(params: *const ScParams) {
    for i in 0..sc_option_count() {
        let name = sc_option_name(i);
        let (lo, hi) = (sc_option_min(i), sc_option_max(i));
        let value = match sc_option_type(i) {
            SC_OPTION_INT => {
                let mut v = 0;
                assert_eq!(sc_params_get_int(params, name, &mut v), ScStatus::Ok);
                v as f64
            }
            SC_OPTION_DOUBLE => {
                let mut v = 0.0;
                assert_eq!(sc_params_get_double(params, name, &mut v), ScStatus::Ok);
                v
            }
            _ => {
                let mut v = false;
                assert_eq!(sc_params_get_bool(params, name, &mut v), ScStatus::Ok);
                f64::from(u8::from(v))
            }
        };
        assert!(
            lo <= value && value <= hi,
            "option {i}: {value} outside [{lo}, {hi}]"
        );
    }
}

fuzz_target!(|data: &[u8]| {
    let mut b = Bytes(data);
    let mut params: *mut ScParams = null_mut();
    // SAFETY: every pointer passed is NULL, a live handle, a NUL-terminated string or a
    // writable value.
    unsafe {
        assert_eq!(sc_params_new(&mut params), ScStatus::Ok);
        for _ in 0..64 {
            if b.is_empty() {
                break;
            }
            let op = b.u8();
            let name = name(&mut b);
            let handle = if op & 0x80 != 0 { null_mut() } else { params };
            let n: *const c_char = if op & 0x40 != 0 {
                null()
            } else {
                name.as_ptr()
            };
            let status = match op % 6 {
                0 => {
                    let v = int(&mut b);
                    let status = sc_params_set_int(handle, n, v);
                    let mut got = 0;
                    if status == ScStatus::Ok {
                        assert_eq!(sc_params_get_int(params, n, &mut got), ScStatus::Ok);
                        assert_eq!(got, v);
                    }
                    status
                }
                1 => {
                    let v = double(&mut b);
                    let status = sc_params_set_double(handle, n, v);
                    let mut got = 0.0;
                    if status == ScStatus::Ok {
                        assert_eq!(sc_params_get_double(params, n, &mut got), ScStatus::Ok);
                        assert_eq!(got.to_bits(), v.to_bits());
                    }
                    status
                }
                2 => {
                    let v = b.u8() & 1 != 0;
                    let status = sc_params_set_bool(handle, n, v);
                    let mut got = !v;
                    if status == ScStatus::Ok {
                        assert_eq!(sc_params_get_bool(params, n, &mut got), ScStatus::Ok);
                        assert_eq!(got, v);
                    }
                    status
                }
                3 => sc_params_get_int(handle, n, &mut 0),
                4 => sc_params_get_double(handle, n, &mut 0.0),
                _ => sc_params_get_bool(handle, n, &mut false),
            };
            assert_ne!(status, ScStatus::Panic);
            if n.is_null() {
                assert_eq!(status, ScStatus::NullArgument);
            }
            assert!(status != ScStatus::Ok || !handle.is_null());
            let i = b.u8() as usize;
            assert_eq!(sc_option_name(i).is_null(), i >= sc_option_count());
            assert_eq!(sc_option_doc(i).is_null(), i >= sc_option_count());
            assert_eq!(sc_option_type(i) == u32::MAX, i >= sc_option_count());
            assert_eq!(sc_option_min(i).is_nan(), i >= sc_option_count());
        }
        check_ranges(params);
        sc_params_free(params);
    }
});
