//! The outer loop's parameters (the schema's group "cartesian", SPEC §16),
//! its formulation (SPEC §19) and the length of an orbit.

use super::*;

/// How the target impedance reaches the torque (schema keyword `formulation`,
/// SPEC §19).
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq)]
pub enum Formulation {
    /// Position-based impedance ("admittance", SPEC §16): the measured wrench
    /// drives the compliant reference (C1), which the joint law tracks. Exact
    /// in free space and against compliant environments; against a rigid one
    /// the loop wrench → p̈_d → q̈_d → τ → wrench is algebraic and chatters
    /// when the arm's apparent mass exceeds M_d (docs/panda.md).
    #[default]
    Admittance,
    /// Torque-level impedance ("impedance", SPEC §19): τ = Jᵀ(q)[K̃ e + B ė]
    /// at the measured pose, the joint law's feedback in the null space of
    /// the task, the networks compensating D, C, G along the *commanded*
    /// motion; the measured wrench never reaches the torque, only the
    /// learning error (against the compliant reference). Passive against
    /// any environment (Hogan 1985; Albu-Schäffer, Ott & Hirzinger 2007).
    Impedance,
    /// The family between the two ("unified", SPEC §19): the convex
    /// combination of the admittance and the impedance torques with the
    /// admittance's share `admittance_share` (Ott, Mukherjee & Nakamura 2010,
    /// whose switched law averages to it).
    Unified,
}

choices!(Formulation {
    "admittance" => Formulation::Admittance,
    "impedance" => Formulation::Impedance,
    "unified" => Formulation::Unified,
});

impl Formulation {
    /// The admittance's share n ∈ [0, 1] of the torque: 1 for
    /// [`Admittance`](Self::Admittance), 0 for [`Impedance`](Self::Impedance),
    /// `share` for [`Unified`](Self::Unified).
    pub fn share(self, share: f64) -> f64 {
        match self {
            Formulation::Admittance => 1.0,
            Formulation::Impedance => 0.0,
            Formulation::Unified => share,
        }
    }
}

/// Parameters of the 6-D target impedance and of the inverse kinematics,
/// every diagonal one by its diagonal (x, y, z of the world frame); the
/// schema's group "cartesian" (SPEC §16). Start from [`Default`] (the
/// schema's defaults).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct CartesianConfig {
    /// Target inertia M_d of the translation (kg), > 0.
    pub md: Vector<3>,
    /// Target damping B_d of the translation (N s/m), ≥ 0; `None`: critically
    /// damped, 2√(K_d M_d), following the filtered K_d.
    pub bd: Option<Vector<3>>,
    /// Target stiffness K_d of the translation (N/m), ≥ 0.
    pub kd: Vector<3>,
    /// Target inertia of the rotation (kg m²), > 0.
    pub md_rot: Vector<3>,
    /// Target damping of the rotation (N m s/rad), ≥ 0; `None`: critical.
    pub bd_rot: Option<Vector<3>>,
    /// Target stiffness of the rotation (N m/rad), ≥ 0; 0 on every axis at
    /// construction: position-only (the orientation is no task).
    pub kd_rot: Vector<3>,
    /// CLIK gain K_P (1/s²), > 0: the pose error e of fk(q_d) obeys ë + K_D ė + K_P e = 0.
    pub clik_kp: f64,
    /// CLIK gain K_D (1/s), > 0.
    pub clik_kd: f64,
    /// Damping λ_p of the least-squares inverse in the translation rows (m/rad), > 0.
    pub clik_lambda: f64,
    /// Damping λ_o of the least-squares inverse in the rotation rows (rad/rad), > 0.
    pub clik_lambda_rot: f64,
    /// Null-space posture stiffness k_0 (1/s²), ≥ 0.
    pub null_k: f64,
    /// Null-space damping d_0 (1/s), ≥ 0.
    pub null_d: f64,
    /// Largest translation error fed to the impedance (m), > 0; `None`: no clipping.
    pub pos_error_max: Option<f64>,
    /// Largest rotation error fed to the impedance (rad), > 0; `None`: no clipping.
    pub rot_error_max: Option<f64>,
    /// Time constant τ_t (s) of the first-order filter on jumps of the
    /// commanded pose and on changes of the stiffness, ≥ 0 (0: none).
    pub target_filter: f64,
    /// Time constant τ_f (s) of the first-order filter on the measured wrench, ≥ 0 (0: none).
    pub force_filter: f64,
    /// Whether the joint controller gets τe = Jᵀ(q) F_e (C5, its law's +τe
    /// feedforward), or zero (the contact acts through (C1) only).
    pub force_feedforward: bool,
    /// How the impedance reaches the torque (SPEC §19).
    pub formulation: Formulation,
    /// The admittance's share n ∈ [0, 1] of the torque for
    /// [`Formulation::Unified`] (ignored otherwise).
    pub admittance_share: f64,
}

impl CartesianConfig {
    /// This configuration with the orientation left free: rotational stiffness 0
    /// (position-only, SPEC §16's 3-D loop).
    pub fn position_only(self) -> Self {
        Self {
            kd_rot: Vector::zeros(),
            ..self
        }
    }

    /// Whether the orientation is a task (some rotational stiffness > 0).
    pub fn orients(&self) -> bool {
        self.kd_rot.iter().any(|k| *k > 0.0)
    }

    /// Validated (each condition named, as SPEC §10).
    pub(super) fn check(&self) -> Result<(), Error> {
        check::positive_vec("Md > 0", "Md", &self.md)?;
        check::positive_vec("Md_rot > 0", "Md_rot", &self.md_rot)?;
        check::nonnegative_vec("Kd ≥ 0", "Kd", &self.kd)?;
        check::nonnegative_vec("Kd_rot ≥ 0", "Kd_rot", &self.kd_rot)?;
        if let Some(b) = &self.bd {
            check::nonnegative_vec("Bd ≥ 0", "Bd", b)?;
            bounded("Bd", b)?;
        }
        if let Some(b) = &self.bd_rot {
            check::nonnegative_vec("Bd_rot ≥ 0", "Bd_rot", b)?;
            bounded("Bd_rot", b)?;
        }
        for (what, v) in [
            ("Md", &self.md),
            ("Kd", &self.kd),
            ("Md_rot", &self.md_rot),
            ("Kd_rot", &self.kd_rot),
        ] {
            bounded(what, v)?;
        }
        check::positive("clik_kp > 0", "clik_kp", self.clik_kp)?;
        check::positive("clik_kd > 0", "clik_kd", self.clik_kd)?;
        check::positive("clik_lambda > 0", "clik_lambda", self.clik_lambda)?;
        check::positive(
            "clik_lambda_rot > 0",
            "clik_lambda_rot",
            self.clik_lambda_rot,
        )?;
        check::nonnegative("null_k ≥ 0", "null_k", self.null_k)?;
        check::nonnegative("null_d ≥ 0", "null_d", self.null_d)?;
        check::nonnegative("target_filter ≥ 0", "target_filter", self.target_filter)?;
        check::nonnegative("force_filter ≥ 0", "force_filter", self.force_filter)?;
        check::nonnegative(
            "0 ≤ admittance_share ≤ 1",
            "admittance_share",
            self.admittance_share,
        )?;
        check::at_most(
            "0 ≤ admittance_share ≤ 1",
            "admittance_share",
            self.admittance_share,
            1.0,
        )?;
        if let Some(e) = self.pos_error_max {
            check::positive("pos_error_max > 0", "pos_error_max", e)?;
        }
        if let Some(e) = self.rot_error_max {
            check::positive("rot_error_max > 0", "rot_error_max", e)?;
        }
        for (what, v) in [
            ("clik_kp", self.clik_kp),
            ("clik_kd", self.clik_kd),
            ("clik_lambda", self.clik_lambda),
            ("clik_lambda_rot", self.clik_lambda_rot),
            ("null_k", self.null_k),
            ("null_d", self.null_d),
            ("target_filter", self.target_filter),
            ("force_filter", self.force_filter),
        ] {
            check::at_most("|value| ≤ 1e9", what, v, PARAM_BOUND)?;
        }
        Ok(())
    }
}

/// The most steps [`CartesianImpedance::orbit`] runs (1000 s at 1 kHz): a
/// path is sampled once a period, so a longer one is refused before any work.
pub const ORBIT_MAX_STEPS: usize = 1_000_000;

/// The steps of an orbit of duration `t` (s) at period `ts` (s):
/// round(t/ts), from 1 to [`ORBIT_MAX_STEPS`]; else an error naming `T`.
pub fn orbit_steps(t: f64, ts: f64) -> Result<usize, Error> {
    check::positive("T > 0", "T", t)?;
    check::positive("Ts > 0", "Ts", ts)?;
    let steps = libm::round(t / ts);
    if !(1.0..=ORBIT_MAX_STEPS as f64).contains(&steps) {
        return Err(Error::Condition {
            condition: "1 ≤ round(T/Ts) ≤ 1e6 steps (an orbit is sampled once a period)",
            lhs: "T/Ts",
            index: None,
            value: t / ts,
        });
    }
    Ok(steps as usize)
}

/// `steps` within [`ORBIT_MAX_STEPS`] and at least one sample to write.
pub(super) fn check_orbit_size(steps: usize, samples: usize) -> Result<(), Error> {
    if steps > ORBIT_MAX_STEPS {
        return Err(Error::Condition {
            condition: "steps ≤ 1e6 (an orbit is sampled once a period)",
            lhs: "steps",
            index: None,
            value: steps as f64,
        });
    }
    if samples == 0 {
        return Err(Error::Condition {
            condition: "nodes ≥ 1",
            lhs: "nodes",
            index: None,
            value: 0.0,
        });
    }
    Ok(())
}
