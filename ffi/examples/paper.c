/* The paper scenario (SPEC §11) from C: adaptimp's controllers through the C
 * ABI, closing the loop with the paper's 2-link arm and wall written here in
 * C (RK4, the arithmetic of src/sim/model.rs, src/sim/environment.rs and
 * src/sim/plant.rs, so the trajectories are those of `cargo run --example
 * paper`). Prints the same SPEC §12 metrics table.
 *
 *   paper [--T seconds]   the three cases (default T = 20 s)
 *   paper --steps K       K state-feedback steps, then free everything
 *                         (for counting heap allocations under valgrind)
 *   paper --torques       applied torques of a fixed input sequence, for
 *                         comparison with Rust and Python
 *   paper --abi-checks    NULL pointers, wrong sizes and bad parameters
 *                         give statuses and messages, never a crash
 *   paper --timing K      time each of K steps through the ABI in closed
 *                         loop (state feedback, paper and robot presets):
 *                         median and 99.9th percentile, as the Rust
 *                         example worst_case does
 */
/* clock_gettime and CLOCK_MONOTONIC are POSIX, not ISO C: declared by
   <time.h> under -std=c11 only with this. */
#define _POSIX_C_SOURCE 199309L

#include "adaptimp.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

/* ---- The paper's arm (SPEC §1) and wall (SPEC §3), as in the Rust core. ---- */

typedef struct {
    double p1, p2, p3, p4, p5, g;
} Arm;

static Arm paper_arm(void) {
    const double m1 = 2.0, m2 = 0.85, l1 = 0.35, l2 = 0.31, g = 9.81;
    const double lc1 = l1 / 2.0, lc2 = l2 / 2.0;
    const double i1 = m1 * l1 * l1 / 4.0, i2 = m2 * l2 * l2 / 4.0;
    Arm a;
    a.p1 = m1 * lc1 * lc1 + m2 * l1 * l1 + i1; /* (59) */
    a.p2 = m2 * lc2 * lc2 + i2;                /* (60) */
    a.p3 = m2 * l1 * lc2;                      /* (61) */
    a.p4 = m1 * lc1 + m2 * l1;                 /* (62), erratum: lc1 */
    a.p5 = m2 * lc2;                           /* (63) */
    a.g = g;
    return a;
}

/* The wall on joint 1 at 0.2 rad: tau_e = max(0, ke d + be dq1) for d > 0. */
static void wall(const double x[2], const double dx[2], double tau_e[2]) {
    const double w = 0.2, ke = 1000.0, be = 10.0;
    const double delta = x[0] - w;
    tau_e[0] = 0.0;
    tau_e[1] = 0.0;
    if (delta > 0.0) {
        const double f = ke * delta + be * dx[0];
        tau_e[0] = f > 0.0 ? f : 0.0;
    }
}

/* D q'' = tau - tau_e - C q' - G, by the closed-form 2x2 solve. */
static void forward_dynamics(const Arm *a, const double q[2], const double dq[2],
                             const double tau[2], const double tau_e[2], double out[2]) {
    const double s1 = sin(q[0]), c1 = cos(q[0]);
    const double s2 = sin(q[1]), c2 = cos(q[1]);
    const double c12 = c1 * c2 - s1 * s2;
    const double h = a->p3 * s2;
    const double r0 = tau[0] - tau_e[0] + h * dq[1] * (2.0 * dq[0] + dq[1]) - a->p4 * a->g * c1 -
                      a->p5 * a->g * c12;
    const double r1 = tau[1] - tau_e[1] - h * dq[0] * dq[0] - a->p5 * a->g * c12;
    const double d11 = a->p1 + a->p2 + 2.0 * a->p3 * c2;
    const double d12 = a->p2 + a->p3 * c2;
    const double det = d11 * a->p2 - d12 * d12;
    out[0] = (a->p2 * r0 - d12 * r1) / det;
    out[1] = (d11 * r1 - d12 * r0) / det;
}

static void accel(const Arm *a, const double x[2], const double dx[2], const double tau[2],
                  double out[2]) {
    double f[2];
    wall(x, dx, f);
    forward_dynamics(a, x, dx, tau, f, out);
}

/* One classical RK4 step of h with tau held; a0 is the acceleration at (x, dx). */
static void rk4(const Arm *a, double h, const double tau[2], double x[2], double dx[2],
                const double a0[2]) {
    double x2[2], v2[2], k2[2], x3[2], v3[2], k3[2], x4[2], v4[2], k4[2];
    for (int i = 0; i < 2; i++) {
        x2[i] = x[i] + 0.5 * h * dx[i];
        v2[i] = dx[i] + 0.5 * h * a0[i];
    }
    accel(a, x2, v2, tau, k2);
    for (int i = 0; i < 2; i++) {
        x3[i] = x[i] + 0.5 * h * v2[i];
        v3[i] = dx[i] + 0.5 * h * k2[i];
    }
    accel(a, x3, v3, tau, k3);
    for (int i = 0; i < 2; i++) {
        x4[i] = x[i] + h * v3[i];
        v4[i] = dx[i] + h * k3[i];
    }
    accel(a, x4, v4, tau, k4);
    for (int i = 0; i < 2; i++) {
        const double xn = x[i] + h / 6.0 * (dx[i] + 2.0 * v2[i] + 2.0 * v3[i] + v4[i]);
        const double vn = dx[i] + h / 6.0 * (a0[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
        x[i] = xn;
        dx[i] = vn;
    }
}

/* The paper's circle (64) at t, as Sinusoid::sample computes it. */
static void circle(double t, AdaptimpSetpoint *sp) {
    const double o[2] = {0.2, 0.2}, a[2] = {0.0, 0.2}, b[2] = {-0.2, 0.0};
    const double w = 3.14159265358979323846;
    const double s = sin(w * t), c = cos(w * t);
    memset(sp, 0, sizeof *sp);
    for (int i = 0; i < 2; i++) {
        sp->x[i] = o[i] + (a[i] * s + b[i] * c);
        sp->dx[i] = w * (a[i] * c - b[i] * s);
        sp->ddx[i] = -w * w * (a[i] * s + b[i] * c);
    }
}

/* ---- Errors. ---- */

static int check(AdaptimpStatus status, const char *what) {
    if (status != ADAPTIMP_STATUS_OK) {
        fprintf(stderr, "%s: status %d: %s\n", what, (int)status, adaptimp_last_error());
        return 0;
    }
    return 1;
}

/* ---- SPEC §12 metrics, accumulated as src/sim/metrics.rs does. ---- */

typedef struct {
    size_t rows, rows_after, sat_rows, contact_rows;
    double sum_z1, sum_z1_after, sum_joint_after[2], max_joint_after[2];
    double peak_contact_after, sum_contact, peak_tau[2], sum_imp_after;
} Metrics;

static void push(Metrics *m, double t, const double x[2], const double dx[2],
                 const double ddx[2], const AdaptimpSetpoint *sp, const double tau_e[2],
                 const AdaptimpCommand *cmd) {
    const double dd = 1.0, cd = 10.0, gd = 60.0, settle = 2.0;
    const int after = t >= settle - 1e-9;
    const double z2 = cmd->z1[0] * cmd->z1[0] + cmd->z1[1] * cmd->z1[1];
    m->rows++;
    m->sum_z1 += z2;
    if (cmd->dtau[0] != 0.0 || cmd->dtau[1] != 0.0) m->sat_rows++;
    const double contact = sqrt(tau_e[0] * tau_e[0] + tau_e[1] * tau_e[1]);
    if (tau_e[0] != 0.0 || tau_e[1] != 0.0) {
        m->contact_rows++;
        m->sum_contact += contact;
    }
    for (int i = 0; i < 2; i++) {
        const double a = fabs(cmd->tau[i]);
        if (a > m->peak_tau[i]) m->peak_tau[i] = a;
    }
    if (after) {
        m->rows_after++;
        m->sum_z1_after += z2;
        double r2 = 0.0;
        for (int i = 0; i < 2; i++) {
            m->sum_joint_after[i] += cmd->z1[i] * cmd->z1[i];
            const double a = fabs(cmd->z1[i]);
            if (a > m->max_joint_after[i]) m->max_joint_after[i] = a;
            const double r = dd * (sp->ddx[i] - ddx[i]) + cd * (sp->dx[i] - dx[i]) +
                             gd * (sp->x[i] - x[i]) - tau_e[i];
            r2 += r * r;
        }
        if (contact > m->peak_contact_after) m->peak_contact_after = contact;
        m->sum_imp_after += r2;
    }
}

/* The paper scenario for controller `law` over T seconds: Ts = 50 µs, one RK4
 * substep, q(0) = [0.25, -0.05]. Returns 0 on success. */
static int run(AdaptimpLaw law, double t_final, Metrics *m) {
    AdaptimpController *ctrl = NULL;
    AdaptimpState *state = NULL;
    if (!check(adaptimp_controller_new_preset(ADAPTIMP_PRESET_PAPER, law, &ctrl), "controller"))
        return 1;
    if (!check(adaptimp_state_new(ctrl, &state), "state")) {
        adaptimp_controller_free(ctrl);
        return 1;
    }
    const Arm arm = paper_arm();
    const double ts = adaptimp_controller_period(ctrl);
    const long steps = lround(t_final / ts);
    double x[2] = {0.25, -0.05}, dx[2] = {0.0, 0.0};
    memset(m, 0, sizeof *m);
    int status = 0;
    for (long k = 0; k < steps; k++) {
        const double t = (double)k * ts;
        double tau_e[2], a0[2];
        AdaptimpSetpoint sp;
        AdaptimpCommand cmd;
        wall(x, dx, tau_e);
        circle(t, &sp);
        if (!check(adaptimp_step(ctrl, state, 2, x, dx, tau_e, &sp, &cmd), "step")) {
            status = 1;
            break;
        }
        forward_dynamics(&arm, x, dx, cmd.tau_sat, tau_e, a0);
        push(m, t, x, dx, a0, &sp, tau_e, &cmd);
        rk4(&arm, ts, cmd.tau_sat, x, dx, a0);
    }
    adaptimp_state_free(state);
    adaptimp_controller_free(ctrl);
    return status;
}

/* Print `label` padded to `width` characters (UTF-8 aware, as Rust's {:<width}). */
static void cell(const char *label, int width) {
    int chars = 0;
    for (const unsigned char *p = (const unsigned char *)label; *p; p++)
        if ((*p & 0xC0) != 0x80) chars++;
    printf(" %s%*s |", label, width - chars > 0 ? width - chars : 0, "");
}

static void table(const Metrics m[3]) {
    const char *names[3] = {"pd", "sf", "of"};
    char v[64];
    printf("| %-36s |", "metric");
    for (int c = 0; c < 3; c++) printf(" %20s |", names[c]);
    printf("\n|--------------------------------------|");
    for (int c = 0; c < 3; c++) printf("----------------------|");
    printf("\n");
    for (int row = 0; row < 11; row++) {
        static const char *labels[11] = {
            "RMS ‖z1‖ (rad)",
            "RMS ‖z1‖, t ≥ 2 s (rad)",
            "RMS z1 per joint, t ≥ 2 s (rad)",
            "max |z1| per joint, t ≥ 2 s (rad)",
            "saturation duty",
            "steps in contact",
            "peak τe, t ≥ 2 s (N m)",
            "mean τe in contact (N m)",
            "peak commanded |τ| (N m)",
            "impedance error RMS, t ≥ 2 s (N m)",
            "rows",
        };
        printf("|");
        cell(labels[row], 36);
        for (int c = 0; c < 3; c++) {
            const Metrics *x = &m[c];
            const double ka = (double)x->rows_after, k = (double)x->rows;
            switch (row) {
            case 0: snprintf(v, sizeof v, "%.5f", sqrt(x->sum_z1 / k)); break;
            case 1: snprintf(v, sizeof v, "%.5f", sqrt(x->sum_z1_after / ka)); break;
            case 2:
                snprintf(v, sizeof v, "%.5f, %.5f", sqrt(x->sum_joint_after[0] / ka),
                         sqrt(x->sum_joint_after[1] / ka));
                break;
            case 3:
                snprintf(v, sizeof v, "%.5f, %.5f", x->max_joint_after[0], x->max_joint_after[1]);
                break;
            case 4: snprintf(v, sizeof v, "%.4f", (double)x->sat_rows / k); break;
            case 5: snprintf(v, sizeof v, "%zu", x->contact_rows); break;
            case 6: snprintf(v, sizeof v, "%.3f", x->peak_contact_after); break;
            case 7:
                snprintf(v, sizeof v, "%.3f",
                         x->contact_rows ? x->sum_contact / (double)x->contact_rows : 0.0);
                break;
            case 8: snprintf(v, sizeof v, "%.1f, %.1f", x->peak_tau[0], x->peak_tau[1]); break;
            case 9: snprintf(v, sizeof v, "%.3f", sqrt(x->sum_imp_after / ka)); break;
            default: snprintf(v, sizeof v, "%zu", x->rows); break;
            }
            printf(" %20s |", v);
        }
        printf("\n");
    }
}

/* K state-feedback steps in closed loop, then free everything. */
static int steps_only(long steps) {
    AdaptimpController *ctrl = NULL;
    AdaptimpState *state = NULL;
    if (!check(adaptimp_controller_new_preset(ADAPTIMP_PRESET_PAPER, ADAPTIMP_LAW_STATE_FEEDBACK,
                                              &ctrl),
               "controller") ||
        !check(adaptimp_state_new(ctrl, &state), "state"))
        return 1;
    const Arm arm = paper_arm();
    const double ts = adaptimp_controller_period(ctrl);
    double x[2] = {0.25, -0.05}, dx[2] = {0.0, 0.0};
    AdaptimpCommand cmd;
    memset(&cmd, 0, sizeof cmd);
    for (long k = 0; k < steps; k++) {
        double tau_e[2], a0[2];
        wall(x, dx, tau_e);
        if (!check(adaptimp_step(ctrl, state, 2, x, dx, tau_e, NULL, &cmd), "step")) return 1;
        forward_dynamics(&arm, x, dx, cmd.tau_sat, tau_e, a0);
        rk4(&arm, ts, cmd.tau_sat, x, dx, a0);
    }
    printf("%ld steps, tau_sat = [%.6f, %.6f] N m\n", steps, cmd.tau_sat[0], cmd.tau_sat[1]);
    adaptimp_state_free(state);
    adaptimp_controller_free(ctrl);
    return 0;
}

static int compare_u32(const void *a, const void *b) {
    const uint32_t x = *(const uint32_t *)a, y = *(const uint32_t *)b;
    return (x > y) - (x < y);
}

static uint32_t percentile(const uint32_t *sorted, long n, double p) {
    return sorted[lround((double)(n - 1) * p)];
}

/* Each adaptimp_step timed with CLOCK_MONOTONIC in closed loop with the arm. */
static int timing(long steps) {
    const AdaptimpPreset presets[2] = {ADAPTIMP_PRESET_PAPER, ADAPTIMP_PRESET_ROBOT};
    uint32_t *ns = malloc(sizeof *ns * (size_t)steps);
    if (ns == NULL || steps < 1) return 1;
    printf("| controller (C ABI) | median (ns) | 99.9th percentile (ns) | max (ns) |\n|---|---:|---:|---:|\n");
    for (int pr = 0; pr < 2; pr++) {
        AdaptimpController *ctrl = NULL;
        AdaptimpState *state = NULL;
        if (!check(adaptimp_controller_new_preset(presets[pr], ADAPTIMP_LAW_STATE_FEEDBACK, &ctrl),
                   "controller") ||
            !check(adaptimp_state_new(ctrl, &state), "state"))
            return 1;
        const Arm arm = paper_arm();
        const double ts = adaptimp_controller_period(ctrl);
        double x[2] = {0.25, -0.05}, dx[2] = {0.0, 0.0};
        for (long k = 0; k < steps; k++) {
            double tau_e[2], a0[2];
            AdaptimpCommand cmd;
            struct timespec t0, t1;
            wall(x, dx, tau_e);
            clock_gettime(CLOCK_MONOTONIC, &t0);
            const AdaptimpStatus st = adaptimp_step(ctrl, state, 2, x, dx, tau_e, NULL, &cmd);
            clock_gettime(CLOCK_MONOTONIC, &t1);
            if (!check(st, "step")) return 1;
            const int64_t d = (int64_t)(t1.tv_sec - t0.tv_sec) * 1000000000 + (t1.tv_nsec - t0.tv_nsec);
            ns[k] = d > (int64_t)UINT32_MAX ? UINT32_MAX : (uint32_t)d;
            forward_dynamics(&arm, x, dx, cmd.tau_sat, tau_e, a0);
            rk4(&arm, ts, cmd.tau_sat, x, dx, a0);
        }
        qsort(ns, (size_t)steps, sizeof *ns, compare_u32);
        printf("| sf (%s) | %u | %u | %u |\n", pr ? "robot, hardened" : "paper",
               percentile(ns, steps, 0.5), percentile(ns, steps, 0.999), ns[steps - 1]);
        adaptimp_state_free(state);
        adaptimp_controller_free(ctrl);
    }
    free(ns);
    return 0;
}

/* The fixed input sequence of tests/test_ffi.py at step k. */
static void inputs(long k, double q[2], double dq[2], double te[2]) {
    const double s = (double)k;
    q[0] = 0.25 + 0.01 * sin(0.1 * s);
    q[1] = -0.05 + 0.01 * cos(0.07 * s);
    dq[0] = 0.1 * cos(0.1 * s);
    dq[1] = -0.1 * sin(0.07 * s);
    te[0] = fmax(0.0, 5.0 * sin(0.05 * s));
    te[1] = 0.0;
}

static int torques(void) {
    const AdaptimpLaw laws[3] = {ADAPTIMP_LAW_PD, ADAPTIMP_LAW_STATE_FEEDBACK,
                                 ADAPTIMP_LAW_OUTPUT_FEEDBACK};
    const char *names[3] = {"pd", "sf", "of"};
    const AdaptimpPreset presets[2] = {ADAPTIMP_PRESET_PAPER, ADAPTIMP_PRESET_ROBOT};
    for (int l = 0; l < 3; l++) {
        for (int preset = 0; preset < 2; preset++) {
            AdaptimpController *ctrl = NULL;
            AdaptimpState *state = NULL;
            if (!check(adaptimp_controller_new_preset(presets[preset], laws[l], &ctrl),
                       "controller") ||
                !check(adaptimp_state_new(ctrl, &state), "state"))
                return 1;
            for (long k = 0; k < 200; k++) {
                double q[2], dq[2], te[2];
                AdaptimpCommand cmd;
                inputs(k, q, dq, te);
                if (!check(adaptimp_step(ctrl, state, 2, q, dq, te, NULL, &cmd), "step")) return 1;
                printf("%s %s %ld %.17g %.17g\n", names[l], preset ? "robot" : "paper", k,
                       cmd.tau_sat[0], cmd.tau_sat[1]);
            }
            adaptimp_state_free(state);
            adaptimp_controller_free(ctrl);
        }
    }
    return 0;
}

/* Every misuse gets a status and a message, never a crash. */
static int abi_checks(void) {
    int failures = 0;
#define EXPECT(call, status, text)                                                           \
    do {                                                                                     \
        AdaptimpStatus got_ = (call);                                                        \
        if (got_ != (status) || strstr(adaptimp_last_error(), (text)) == NULL) {             \
            fprintf(stderr, "FAILED %s: status %d, message \"%s\"\n", #call, (int)got_,      \
                    adaptimp_last_error());                                                  \
            failures++;                                                                      \
        } else {                                                                             \
            printf("ok %-60.60s -> %s\n", #call, adaptimp_last_error());                     \
        }                                                                                    \
    } while (0)
    AdaptimpController *ctrl = NULL;
    AdaptimpState *state = NULL;
    AdaptimpCommand cmd;
    AdaptimpParams p;
    double q[3] = {0.1, 0.2, 0.3}, dq[3] = {0, 0, 0}, te[3] = {0, 0, 0};
    double snapshot[8] = {0};
    EXPECT(adaptimp_controller_new(NULL, &ctrl), ADAPTIMP_STATUS_NULL_POINTER, "params is NULL");
    EXPECT(adaptimp_params_default(&p, 8, ADAPTIMP_LAW_PD, ADAPTIMP_PRESET_PAPER),
           ADAPTIMP_STATUS_BAD_SIZE, "1 … 7");
    EXPECT(adaptimp_params_default(&p, 2, ADAPTIMP_LAW_STATE_FEEDBACK, ADAPTIMP_PRESET_PAPER),
           ADAPTIMP_STATUS_OK, "");
    p.kzeta[1] = 50.0;
    EXPECT(adaptimp_controller_new(&p, &ctrl), ADAPTIMP_STATUS_INVALID_CONFIG,
           "2·Kzeta − 1 − Kp²[1] = -1");
    p.kzeta[1] = 60.0;
    p.n = 5; /* a 2-joint struct given n = 5: joints 3 … 5 have no gains */
    EXPECT(adaptimp_controller_new(&p, &ctrl), ADAPTIMP_STATUS_INVALID_CONFIG, "K1[2] = 0");
    p.n = 2;
    {
        /* n > 3 without centres: the rule's centres along the trajectory (SPEC §18). */
        AdaptimpParams p5;
        AdaptimpController *five = NULL;
        EXPECT(adaptimp_params_default(&p5, 5, ADAPTIMP_LAW_STATE_FEEDBACK, ADAPTIMP_PRESET_ROBOT),
               ADAPTIMP_STATUS_OK, "");
        EXPECT(adaptimp_controller_new(&p5, &five), ADAPTIMP_STATUS_OK, "");
        adaptimp_controller_free(five);
    }
    EXPECT(adaptimp_controller_new(&p, &ctrl), ADAPTIMP_STATUS_OK, "");
    EXPECT(adaptimp_state_new(ctrl, NULL), ADAPTIMP_STATUS_NULL_POINTER, "out is NULL");
    EXPECT(adaptimp_state_new(ctrl, &state), ADAPTIMP_STATUS_OK, "");
    EXPECT(adaptimp_step(NULL, state, 2, q, dq, te, NULL, &cmd), ADAPTIMP_STATUS_NULL_POINTER,
           "ctrl is NULL");
    EXPECT(adaptimp_step(ctrl, state, 3, q, dq, te, NULL, &cmd), ADAPTIMP_STATUS_BAD_SIZE,
           "n = 3, but the controller has 2 joints");
    EXPECT(adaptimp_step(ctrl, state, 2, q, NULL, te, NULL, &cmd),
           ADAPTIMP_STATUS_MISSING_VELOCITY, "pass dq");
    q[0] = NAN;
    EXPECT(adaptimp_step(ctrl, state, 2, q, dq, te, NULL, &cmd), ADAPTIMP_STATUS_NON_FINITE,
           "x[0] is not finite");
    q[0] = 0.1;
    EXPECT(adaptimp_step(ctrl, state, 2, q, dq, te, NULL, NULL), ADAPTIMP_STATUS_NULL_POINTER,
           "out is NULL");
    EXPECT(adaptimp_step(ctrl, state, 2, q, dq, te, NULL, &cmd), ADAPTIMP_STATUS_OK, "");
    if (adaptimp_state_steps(state) != 1) {
        fprintf(stderr, "FAILED: the failed steps changed the state\n");
        failures++;
    }
    EXPECT(adaptimp_state_save(state, snapshot, 8, NULL), ADAPTIMP_STATUS_BAD_SIZE,
           "too short");
    EXPECT(adaptimp_state_restore(ctrl, state, snapshot, 8), ADAPTIMP_STATUS_BAD_SNAPSHOT,
           "snapshot");
    /* A refused step returns the fallback torque (here: the last one, held). */
    const double held0 = cmd.tau_sat[0];
    q[0] = NAN;
    EXPECT(adaptimp_step(ctrl, state, 2, q, dq, te, NULL, &cmd), ADAPTIMP_STATUS_NON_FINITE,
           "not finite");
    q[0] = 0.1;
    if (cmd.tau_sat[0] != held0 || !adaptimp_state_fault(state, NULL)) {
        fprintf(stderr, "FAILED: no fallback torque or no fault recorded\n");
        failures++;
    }
    EXPECT(adaptimp_state_clear_fault(state), ADAPTIMP_STATUS_OK, "");
    if (adaptimp_state_fault(state, NULL)) {
        fprintf(stderr, "FAILED: the fault was not cleared\n");
        failures++;
    }
    EXPECT(adaptimp_state_reset(NULL), ADAPTIMP_STATUS_NULL_POINTER, "state is NULL");
    adaptimp_state_free(state);
    adaptimp_controller_free(ctrl);
    adaptimp_controller_free(NULL);
    adaptimp_state_free(NULL);
    printf("%d failed\n", failures);
    return failures != 0;
}

int main(int argc, char **argv) {
    double t_final = 20.0;
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--T") == 0 && i + 1 < argc) {
            t_final = atof(argv[++i]);
        } else if (strcmp(argv[i], "--steps") == 0 && i + 1 < argc) {
            return steps_only(atol(argv[++i]));
        } else if (strcmp(argv[i], "--torques") == 0) {
            return torques();
        } else if (strcmp(argv[i], "--abi-checks") == 0) {
            return abi_checks();
        } else if (strcmp(argv[i], "--timing") == 0 && i + 1 < argc) {
            return timing(atol(argv[++i]));
        } else {
            fprintf(stderr,
                    "usage: %s [--T seconds | --steps K | --torques | --abi-checks | --timing K]\n",
                    argv[0]);
            return 2;
        }
    }
    printf("adaptimp %s through the C ABI: paper scenario, T = %g s, Ts = 50 µs, 1 RK4 substep\n",
           adaptimp_version(), t_final);
    const AdaptimpLaw laws[3] = {ADAPTIMP_LAW_PD, ADAPTIMP_LAW_STATE_FEEDBACK,
                                 ADAPTIMP_LAW_OUTPUT_FEEDBACK};
    Metrics m[3];
    for (int c = 0; c < 3; c++)
        if (run(laws[c], t_final, &m[c]) != 0) return 1;
    table(m);
    return 0;
}
