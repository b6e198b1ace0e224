//! The extension module `adaptimp._adaptimp`: what it exports, and its
//! initialisation.

use pyo3::prelude::*;

/// Adaptive neural impedance control with input saturation (He, Dong & Sun,
/// IEEE TSMC 2016): the compiled core for arms of 1 to 7 joints. Use the
/// `adaptimp` package, which wraps this module.
#[pymodule]
#[pyo3(name = "_adaptimp")]
mod adaptimp_module {
    use pyo3::prelude::*;

    #[pymodule_export]
    use crate::tuning::{
        assess_posture, default_task, plane_normal, pose_circle, pose_metrics, posture_needs,
        suggest, table_metrics,
    };
    #[pymodule_export]
    use crate::{
        defaults, metrics, schema_table, simulate, simulate_many, simulate_mujoco,
        simulate_mujoco_many, PyArm, PyController, PyPlanarArm,
    };

    #[pymodule_export]
    use crate::callback_loop::simulate_mujoco_callback;
    #[pymodule_export]
    use crate::cartesian::{centres_along, PyCartesian, PyChain};
    #[pymodule_export]
    use crate::cartesian_step::PyCartesianStep;
    #[pymodule_export]
    use crate::chain::operational_inertia;
    #[pymodule_export]
    use crate::computed::PyComputedTorque;
    #[pymodule_export]
    use crate::description::{arm_from_mujoco, description_kind, estimate_effort, read_arm};
    #[pymodule_export]
    use crate::measurement::PyMeasurement;
    #[pymodule_export]
    use crate::tabulate::{tabulate_joints, tabulate_path};

    #[pymodule_init]
    fn init(m: &Bound<'_, PyModule>) -> PyResult<()> {
        m.add("__version__", env!("CARGO_PKG_VERSION"))?;
        m.add("MAX_JOINTS", crate::MAX_JOINTS)?;
        m.add("EFFORT_ACCEL", adaptimp::dynamic::EFFORT_ACCEL)?;
        m.add("N_NODES", adaptimp::types::grid_nodes(2))?;
        // Load NumPy's C API now, at import: loading it lazily inside a call
        // can meet a pending KeyboardInterrupt and fail with a panic.
        let _ = numpy::PyArray1::<f64>::zeros(m.py(), 0, false);
        Ok(())
    }
}
