//! [`Sim::from_python`]: a handle from the `mujoco` Python package's objects.

use crate::{Library, RawParts, Sim, Span, Warnings};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use std::ffi::c_void;
use std::path::{Path, PathBuf};

fn load_error(e: crate::Error) -> PyErr {
    PyValueError::new_err(e.to_string())
}

/// The MuJoCo library in the directory of the imported `mujoco` package.
fn library_path(mujoco: &Bound<'_, PyModule>) -> PyResult<PathBuf> {
    let file: String = mujoco.getattr("__file__")?.extract()?;
    let dir = Path::new(&file).parent().ok_or_else(|| {
        PyValueError::new_err(format!("mujoco.__file__ = {file:?} has no directory"))
    })?;
    let mut found: Vec<PathBuf> = std::fs::read_dir(dir)
        .map_err(|e| PyValueError::new_err(format!("cannot list {}: {e}", dir.display())))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| {
            p.file_name().and_then(|n| n.to_str()).is_some_and(|n| {
                (n.starts_with("libmujoco.so")
                    || (n.starts_with("libmujoco") && n.ends_with(".dylib")))
                    || n.eq_ignore_ascii_case("mujoco.dll")
            })
        })
        .collect();
    found.sort();
    found.into_iter().next().ok_or_else(|| {
        PyValueError::new_err(format!(
            "no MuJoCo library (libmujoco.so*, libmujoco*.dylib, mujoco.dll) beside {file}"
        ))
    })
}

/// A float64, C-contiguous NumPy view of MuJoCo's memory (not a copy) with
/// `len` elements, and the object that owns it.
fn span(
    data: &Bound<'_, PyAny>,
    name: &str,
    len: usize,
    writable: bool,
    keep: &mut Vec<Py<PyAny>>,
) -> PyResult<Span> {
    let arr = data.getattr(name)?;
    let bad = |why: &str| PyTypeError::new_err(format!("MjData.{name}: {why}"));
    if !arr.getattr("dtype")?.eq("float64")? {
        return Err(bad("not a float64 array"));
    }
    let flags = arr.getattr("flags")?;
    if !flags.get_item("C_CONTIGUOUS")?.extract::<bool>()? {
        return Err(bad("not C-contiguous"));
    }
    if writable && !flags.get_item("WRITEABLE")?.extract::<bool>()? {
        return Err(bad("read-only"));
    }
    let size: usize = arr.getattr("size")?.extract()?;
    if size != len {
        return Err(bad(&format!("{size} values, the model needs {len}")));
    }
    if len == 0 {
        // Nothing to read or write (NumPy may hand out a fresh empty array).
        return Ok(Span {
            ptr: std::ptr::NonNull::<f64>::dangling().as_ptr(),
            len,
        });
    }
    if arr.getattr("base")?.is_none() {
        return Err(bad("a copy, not a view of MuJoCo's memory"));
    }
    let addr: usize = arr
        .getattr("__array_interface__")?
        .get_item("data")?
        .get_item(0)?
        .extract()?;
    if addr == 0 || !addr.is_multiple_of(std::mem::align_of::<f64>()) {
        return Err(bad("misaligned"));
    }
    keep.push(arr.unbind());
    Ok(Span {
        ptr: addr as *mut f64,
        len,
    })
}

/// `data.warning.number` and `.lastinfo`: int32 views, one per warning kind.
fn warnings(data: &Bound<'_, PyAny>, keep: &mut Vec<Py<PyAny>>) -> PyResult<Warnings> {
    let w = data.getattr("warning")?;
    let mut field = |name: &str| -> PyResult<(usize, usize, usize)> {
        let arr = w.getattr(name)?;
        let bad = |why: &str| PyTypeError::new_err(format!("MjData.warning.{name}: {why}"));
        if !arr.getattr("dtype")?.eq("int32")? {
            return Err(bad("not an int32 array"));
        }
        if arr.getattr("ndim")?.extract::<usize>()? != 1 || arr.getattr("base")?.is_none() {
            return Err(bad("not a 1-D view of MuJoCo's memory"));
        }
        let count: usize = arr.getattr("size")?.extract()?;
        let stride: isize = arr.getattr("strides")?.get_item(0)?.extract()?;
        let addr: usize = arr
            .getattr("__array_interface__")?
            .get_item("data")?
            .get_item(0)?
            .extract()?;
        let stride = usize::try_from(stride).map_err(|_| bad("negative stride"))?;
        if addr == 0 || !addr.is_multiple_of(4) || !stride.is_multiple_of(4) || stride < 8 {
            return Err(bad("unexpected layout"));
        }
        keep.push(arr.unbind());
        Ok((addr, stride, count))
    };
    let (number, s1, c1) = field("number")?;
    let (lastinfo, s2, c2) = field("lastinfo")?;
    if s1 != s2 || c1 != c2 {
        return Err(PyTypeError::new_err(
            "MjData.warning: number and lastinfo disagree in layout",
        ));
    }
    Ok(Warnings {
        number: number as *const i32,
        lastinfo: lastinfo as *const i32,
        stride: s1,
        count: c1,
    })
}

impl Sim {
    /// A handle on `data`, a `mujoco.MjData` made for `model`, a
    /// `mujoco.MjModel`, both of the imported `mujoco` package, whose library
    /// it opens (see [`Library::open`]). Both objects and the arrays read
    /// are kept alive by the handle.
    ///
    /// Raises `TypeError` for objects of another kind, `ValueError` if the
    /// library cannot be opened, is another version than the package's, or
    /// `data` is in use by another handle.
    pub fn from_python(model: &Bound<'_, PyAny>, data: &Bound<'_, PyAny>) -> PyResult<Sim> {
        let py = model.py();
        let mujoco = py.import("mujoco")?;
        if !model.is_instance(&mujoco.getattr("MjModel")?)? {
            return Err(PyTypeError::new_err("model must be a mujoco.MjModel"));
        }
        if !data.is_instance(&mujoco.getattr("MjData")?)? {
            return Err(PyTypeError::new_err("data must be a mujoco.MjData"));
        }
        let m_addr: usize = model.getattr("_address")?.extract()?;
        let d_addr: usize = data.getattr("_address")?.extract()?;
        let dm_addr: usize = data.getattr("model")?.getattr("_address")?.extract()?;
        if m_addr == 0 || d_addr == 0 || dm_addr != m_addr {
            return Err(PyValueError::new_err("data was not made for this model"));
        }
        let path = library_path(&mujoco)?;
        // SAFETY: the file is the MuJoCo library of the imported `mujoco`
        // package (its extension modules link it from that directory), so it
        // is already loaded and has mujoco.h's functions.
        let lib = unsafe { Library::open(&path) }.map_err(load_error)?;
        let version: i32 = mujoco.call_method0("mj_version")?.extract()?;
        if lib.version() != version {
            return Err(PyValueError::new_err(format!(
                "{} is MuJoCo {}, the mujoco package {version}",
                path.display(),
                lib.version()
            )));
        }
        let size = |name: &str| -> PyResult<usize> { model.getattr(name)?.extract() };
        let (nq, nv, nu) = (size("nq")?, size("nv")?, size("nu")?);
        let (nsensordata, nsite, nbody) = (size("nsensordata")?, size("nsite")?, size("nbody")?);
        let nuserdata = size("nuserdata")?;
        let mut keep: Vec<Py<PyAny>> = vec![model.clone().unbind(), data.clone().unbind()];
        let parts = RawParts {
            model: m_addr as *const c_void,
            data: d_addr as *mut c_void,
            qpos: span(data, "qpos", nq, false, &mut keep)?,
            qvel: span(data, "qvel", nv, false, &mut keep)?,
            qacc: span(data, "qacc", nv, false, &mut keep)?,
            ctrl: span(data, "ctrl", nu, true, &mut keep)?,
            qfrc_applied: span(data, "qfrc_applied", nv, true, &mut keep)?,
            sensordata: span(data, "sensordata", nsensordata, false, &mut keep)?,
            site_xpos: span(data, "site_xpos", 3 * nsite, false, &mut keep)?,
            site_xmat: span(data, "site_xmat", 9 * nsite, false, &mut keep)?,
            xpos: span(data, "xpos", 3 * nbody, false, &mut keep)?,
            subtree_com: span(data, "subtree_com", 3 * nbody, false, &mut keep)?,
            cfrc_ext: span(data, "cfrc_ext", 6 * nbody, false, &mut keep)?,
            userdata: span(data, "userdata", nuserdata, true, &mut keep)?,
            warnings: warnings(data, &mut keep)?,
            nv,
        };
        // SAFETY: the library is the package's (checked version), model and
        // data are the package's objects (isinstance) and a pair (data.model
        // is model); every span is a float64 view of data's own memory with
        // the field's length for this model (checked), as are the warning
        // counters; all of them are kept alive in `keep`.
        unsafe { Sim::from_raw(lib, parts, Box::new(keep)) }.map_err(load_error)
    }
}
