//! Many runs at once (sweeps), in parallel, each run's error kept with its row.

use super::dynamic::{ArmSpec, Hooks, Owned, ParamError, RunError};
use super::{arrays::*, controller::*, errors::*, hooks::*, models::*, params::*, runs::*};
use super::{dynamic, mujoco};
use adaptimp::control::config::Law;
use adaptimp::schema::Preset;
use adaptimp::sim::model::TwoLinkArm;
use pyo3::exceptions::{PyRuntimeError, PyTypeError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use std::sync::Mutex;
use std::time::{Duration, Instant};

/// One run of a sweep, parsed while the GIL is held; a run whose parameters
/// cannot make a controller or an arm is its error message.
pub(super) struct Job {
    pub(super) law: Law,
    pub(super) items: Vec<(String, Owned)>,
    pub(super) arm: ArmSpec,
}

/// A [`ParamError`]'s message, as `config_error` words it.
pub(super) fn param_message(e: ParamError) -> String {
    match e.name {
        Some(name) => format!("{name}: {}", e.error),
        None => e.error.to_string(),
    }
}

/// Stops a run when asked (from the thread that watches for signals).
pub(super) struct StopHooks<'a>(&'a std::sync::atomic::AtomicBool);

impl Hooks for StopHooks<'_> {
    fn tick(&mut self, _done: u64, _total: u64) -> bool {
        !self.0.load(std::sync::atomic::Ordering::Relaxed)
    }
}

/// One job, start to end, on the calling thread: its SPEC §12 metrics or the
/// error's message.
pub(super) fn run_job(
    job: &Result<Job, String>,
    stop: &std::sync::atomic::AtomicBool,
) -> Result<dynamic::Metrics, String> {
    let job = job.as_ref().map_err(Clone::clone)?;
    let mut core =
        dynamic::build(2, Preset::Paper, job.law, &job.items, None, None).map_err(param_message)?;
    let mut hooks = StopHooks(stop);
    core.simulate(&job.arm, &job.items, None, None, u64::MAX, &mut hooks)
        .map(|(_, m)| m)
        .map_err(run_message)
}

/// Run every job of `jobs` — tuples (case, params, arm) of the paper's 2-joint
/// arm (`arm` a `TwoLinkArm`, or None for the arm of `params`) — on `threads`
/// threads (all cores if None), each run single-threaded, with the GIL
/// released. Returns, in order, each run's SPEC §12 metrics (a dict) or its
/// error message (a str; also for parameters that make no controller or no
/// arm): one failing run never stops the others. Results
/// equal those of running the jobs one by one, bit for bit. Ctrl-C stops the
/// batch (`KeyboardInterrupt`) within 50 ms; `progress(done, total)` is called
/// as runs finish, at most every 50 ms.
#[pyfunction]
#[pyo3(signature = (jobs, threads=None, progress=None))]
pub(super) fn simulate_many<'py>(
    py: Python<'py>,
    jobs: &Bound<'py, PyList>,
    threads: Option<i64>,
    progress: Option<Py<PyAny>>,
) -> PyResult<Bound<'py, PyList>> {
    let mut parsed = Vec::with_capacity(jobs.len());
    for job in jobs.iter() {
        let (case, params, arm): (String, Bound<'py, PyDict>, Bound<'py, PyAny>) = job.extract()?;
        let given = if arm.is_none() {
            None
        } else if let Ok(a) = arm.cast::<PyArm>() {
            Some(ArmSpec::Paper(a.get().inner))
        } else {
            return Err(PyTypeError::new_err(
                "a sweep's arm must be a TwoLinkArm or None",
            ));
        };
        // The values are the run's: an error here is that run's error row.
        let job = (|| -> PyResult<Result<Job, String>> {
            let law = match law_of(&case) {
                Ok(law) => law,
                Err(e) => return Ok(Err(Python::attach(|py| e.value(py).to_string()))),
            };
            let items = items(&params)?;
            let arm = match given {
                Some(arm) => arm,
                None => {
                    let s = match dynamic::scenario::<2>(Preset::Paper, law, &items) {
                        Ok(s) => s,
                        Err(e) => return Ok(Err(param_message(e))),
                    };
                    match TwoLinkArm::new(s.arm.resolve()) {
                        Ok(a) => ArmSpec::Paper(a),
                        Err(e) => return Ok(Err(param_message(e.into()))),
                    }
                }
            };
            Ok(Ok(Job { law, items, arm }))
        })()?;
        parsed.push(job);
    }
    let results = in_parallel(py, &parsed, threads, progress, |job, stop| {
        run_job(job, stop)
    })?;
    let out = PyList::empty(py);
    for r in results {
        match r {
            Ok(m) => out.append(metrics_to_dict(py, m)?)?,
            Err(msg) => out.append(msg)?,
        }
    }
    Ok(out)
}

/// Run `run` on every job on `threads` threads (all cores if None; at most
/// one per job; fewer than one refused by name) with the GIL released, in order of the results; this thread watches for signals
/// and reports progress every 50 ms (Ctrl-C stops the remaining runs and
/// raises `KeyboardInterrupt`).
pub(super) fn in_parallel<J: Sync>(
    py: Python<'_>,
    jobs: &[J],
    threads: Option<i64>,
    progress: Option<Py<PyAny>>,
    run: impl Fn(&J, &std::sync::atomic::AtomicBool) -> Result<dynamic::Metrics, String> + Sync,
) -> PyResult<Vec<Result<dynamic::Metrics, String>>> {
    use rayon::prelude::*;
    use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
    // More threads than jobs would only be started to idle (10⁴ of them
    // take seconds to start): at most one per job. 0: rayon's every core.
    let threads = match threads {
        None => 0,
        Some(t) if t >= 1 => usize::try_from(t)
            .unwrap_or(usize::MAX)
            .min(jobs.len().max(1)),
        Some(t) => {
            return Err(ConfigError::new_err(format!(
                "threads must be ≥ 1 (None: every core), got {t}"
            )))
        }
    };
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| PyRuntimeError::new_err(format!("cannot start the thread pool: {e}")))?;
    let stop = AtomicBool::new(false);
    let done = AtomicUsize::new(0);
    let total = jobs.len();
    let mut interrupted: Option<PyErr> = None;
    let results = py.detach(|| {
        std::thread::scope(|scope| {
            let worker = scope.spawn(|| {
                pool.install(|| {
                    jobs.par_iter()
                        .map(|job| {
                            let r = run(job, &stop);
                            done.fetch_add(1, Ordering::Relaxed);
                            r
                        })
                        .collect::<Vec<_>>()
                })
            });
            // This thread watches for signals and reports progress, every
            // 50 ms, and notices the end within 10 ms.
            let mut last = Instant::now();
            while !worker.is_finished() {
                std::thread::sleep(Duration::from_millis(10));
                if last.elapsed() < CHECK_EVERY {
                    continue;
                }
                last = Instant::now();
                let stopped = Python::attach(|py| {
                    let r = py.check_signals().and_then(|()| match &progress {
                        Some(cb) => cb
                            .call1(py, (done.load(Ordering::Relaxed), total))
                            .map(|_| ()),
                        None => Ok(()),
                    });
                    r.err()
                });
                if let Some(e) = stopped {
                    interrupted = Some(e);
                    stop.store(true, Ordering::Relaxed);
                    break;
                }
            }
            worker.join()
        })
    });
    if let Some(e) = interrupted {
        return Err(e);
    }
    results.map_err(|_| PyRuntimeError::new_err("a sweep's worker thread panicked"))
}

/// A MuJoCo job as Python gives it: (controller, model, data, spec, params, T, settle).
pub(super) type PyMujocoJob<'py> = (
    Bound<'py, PyController>,
    Bound<'py, PyAny>,
    Bound<'py, PyAny>,
    Bound<'py, PyDict>,
    Bound<'py, PyDict>,
    f64,
    f64,
    Option<PyReference<'py>>,
);

/// One MuJoCo run of a sweep: its controller, plant and settings.
pub(super) struct MujocoJob {
    pub(super) ctrl: Py<PyController>,
    pub(super) sim: Mutex<adaptimp_mujoco::Sim>,
    pub(super) spec: mujoco::MujocoSpec,
    pub(super) items: Vec<(String, Owned)>,
    pub(super) t_final: f64,
    pub(super) settle: f64,
    /// The commanded setpoints of every row (K × n each), or the controller's own trajectory.
    pub(super) reference: Option<[Vec<f64>; 3]>,
}

/// The error of a run as a sweep reports it.
pub(super) fn run_message(e: RunError) -> String {
    match e {
        RunError::Stopped => "stopped".to_owned(),
        RunError::Plant(f) => f.message,
        RunError::Memory(rows) => format!("cannot allocate the records of {rows} rows"),
        RunError::Core(e, None) => python_names(e).to_string(),
        RunError::Core(e, Some(k)) => format!("row {k}: {}", python_names(e)),
    }
}

/// Run every job of `jobs` — tuples (controller, model, data, spec, params,
/// T, settle) as for `simulate_mujoco`, each with its own controller and
/// `MjData` — on `threads` threads (all cores if None), with the GIL
/// released, MuJoCo driven through its C library. Returns, in order, each
/// run's SPEC §12 metrics (a dict) or its error message (a str); results
/// equal those of running each alone. Ctrl-C stops the batch within 50 ms;
/// `progress(done, total)` is called as runs finish.
#[pyfunction]
#[pyo3(signature = (jobs, threads=None, progress=None))]
pub(super) fn simulate_mujoco_many<'py>(
    py: Python<'py>,
    jobs: &Bound<'py, PyList>,
    threads: Option<i64>,
    progress: Option<Py<PyAny>>,
) -> PyResult<Bound<'py, PyList>> {
    let mut parsed = Vec::with_capacity(jobs.len());
    for job in jobs.iter() {
        let (ctrl, model, data, spec, params, t_final, settle, reference): PyMujocoJob<'py> =
            job.extract()?;
        let reference = reference_tables(ctrl.get().n, reference.as_ref())?;
        parsed.push(MujocoJob {
            ctrl: ctrl.unbind(),
            sim: Mutex::new(adaptimp_mujoco::Sim::from_python(&model, &data)?),
            spec: mujoco_spec(&spec)?,
            items: items(&params)?,
            t_final,
            settle,
            reference,
        });
    }
    let results = in_parallel(py, &parsed, threads, progress, |job, stop| {
        let run = dynamic::MujocoRun {
            t_final: job.t_final,
            settle: job.settle,
            every: u64::MAX,
            items: &job.items,
            reference: job
                .reference
                .as_ref()
                .map(|[x, dx, ddx]| [x.as_slice(), dx.as_slice(), ddx.as_slice()]),
            fault: None,
        };
        let mut hooks = StopHooks(stop);
        let mut sim = job.sim.lock().unwrap_or_else(|p| p.into_inner());
        let mut tracker = job.ctrl.get().inner.write_blocking();
        tracker
            .simulate_mujoco(&mut sim, &job.spec, &run, &mut hooks)
            .map(|(_, m)| m)
            .map_err(run_message)
    })?;
    drop(parsed);
    let out = PyList::empty(py);
    for r in results {
        match r {
            Ok(m) => out.append(metrics_to_dict(py, m)?)?,
            Err(msg) => out.append(msg)?,
        }
    }
    Ok(out)
}
