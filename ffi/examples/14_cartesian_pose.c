/* A 7-joint arm's 6-D Cartesian loop (SPEC §16), the same in Rust
 * (examples/14_cartesian_pose.rs), Python (examples/14_cartesian_pose.py)
 * and C: the Franka Emika Panda's kinematics from its joint data (written
 * here, as the URDF of example-robot-data has them), the core's Cartesian
 * controller through the C ABI (6-D outer loop, hardened state feedback with
 * RBF centres along the joint orbit), and a simple plant: decoupled joint
 * inertias I q'' = sat(tau) - J^T F_e, no gravity, against a table (a penalty
 * plane, k_e = 5000 N/m, b_e = 50 N s/m).
 *
 * The tool goes 5 cm forward and 4 cm down in 1 s (a quintic) while turning
 * 20 degrees about the vertical: 1 cm into the table. Then it holds. Prints
 * the pose error during the motion, the contact force against what the
 * target impedance prescribes, (16.1), and the torques: the same figures as
 * the Rust and Python examples.
 *
 *   14_cartesian_pose [--T seconds]   the run (default T = 2 s)
 *   14_cartesian_pose --abi-checks    bad chains, bad targets, wrong sizes:
 *                                     statuses and messages, never a crash
 */
#include "adaptimp.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define N 7
#define TS 1e-3

static const double PI = 3.14159265358979323846;
/* The plant's joint inertias (kg m^2): 1/(D^-1)_ii of the Panda at home. */
static const double INERTIA[N] = {0.27, 0.97, 0.54, 0.40, 0.037, 0.034, 0.0065};
/* The Panda's torque limits (N m) and home posture (rad, the SRDF's numbers). */
static const double TAU_MAX[N] = {87.0, 87.0, 87.0, 87.0, 12.0, 12.0, 12.0};
static const double HOME[N] = {0.0, -0.785398, 0.0, -2.35619, 0.0, 1.5707, 0.785398};
/* The table: stiffness (N/m), damping (N s/m), how far below the home TCP (m). */
static const double KE = 5000.0, BE = 50.0, BELOW = 0.03;

static int check(AdaptimpStatus status, const char *what) {
    if (status != ADAPTIMP_STATUS_OK) {
        fprintf(stderr, "%s: status %d: %s\n", what, (int)status, adaptimp_last_error());
        return 0;
    }
    return 1;
}

/* The Panda to its tool centre point, from the URDF's joint data: seven
 * revolute joints about their z axes with origins (xyz, roll), the flange,
 * the hand's -45 degrees about z, the TCP. */
static AdaptimpStatus panda(AdaptimpChain **out) {
    static const double xyz[N][3] = {{0.0, 0.0, 0.333},   {0.0, 0.0, 0.0}, {0.0, -0.316, 0.0},
                                     {0.0825, 0.0, 0.0},  {-0.0825, 0.384, 0.0},
                                     {0.0, 0.0, 0.0},     {0.088, 0.0, 0.0}};
    const double roll[N] = {0.0, -PI / 2, PI / 2, PI / 2, -PI / 2, PI / 2, PI / 2};
    const double zero[3] = {0.0, 0.0, 0.0};
    AdaptimpJoint joints[N + 2];
    memset(joints, 0, sizeof joints);
    for (int i = 0; i < N; i++) {
        const double rpy[3] = {roll[i], 0.0, 0.0};
        joints[i].kind = ADAPTIMP_JOINT_KIND_REVOLUTE;
        joints[i].axis[2] = 1.0;
        AdaptimpStatus s = adaptimp_transform_xyz_rpy(xyz[i], rpy, &joints[i].origin);
        if (s != ADAPTIMP_STATUS_OK) return s;
    }
    const double flange[3] = {0.0, 0.0, 0.107}, hand[3] = {0.0, 0.0, -PI / 4};
    const double tcp[3] = {0.0, 0.0, 0.1034};
    joints[N].kind = ADAPTIMP_JOINT_KIND_FIXED;
    joints[N + 1].kind = ADAPTIMP_JOINT_KIND_FIXED;
    AdaptimpTransform tip;
    AdaptimpStatus s = adaptimp_transform_xyz_rpy(flange, zero, &joints[N].origin);
    if (s == ADAPTIMP_STATUS_OK) s = adaptimp_transform_xyz_rpy(zero, hand, &joints[N + 1].origin);
    if (s == ADAPTIMP_STATUS_OK) s = adaptimp_transform_xyz_rpy(tcp, zero, &tip);
    if (s != ADAPTIMP_STATUS_OK) return s;
    return adaptimp_chain_new(joints, N + 2, &tip, out);
}

/* The commanded pose at t (s): from (p0, R0), 5 cm along x, 4 cm down and 20
 * degrees about z in 1 s (10 s^3 - 15 s^4 + 6 s^5), then held. */
static void target(const double p0[3], double r0[3][3], double t, AdaptimpPoseTarget *c) {
    const double s = t < 0.0 ? 0.0 : (t > 1.0 ? 1.0 : t);
    const double f = s * s * s * (10.0 - 15.0 * s + 6.0 * s * s);
    const double df = 30.0 * s * s * (1.0 - s) * (1.0 - s);
    const double ddf = 60.0 * s * (1.0 - s) * (1.0 - 2.0 * s);
    const double d[3] = {0.05, 0.0, -0.04};
    const double yaw = 20.0 * (PI / 180.0);
    const double cz = cos(f * yaw), sz = sin(f * yaw);
    const double rz[3][3] = {{cz, -sz, 0.0}, {sz, cz, 0.0}, {0.0, 0.0, 1.0}};
    for (int i = 0; i < 3; i++) {
        c->p[i] = p0[i] + f * d[i];
        c->dp[i] = df * d[i];
        c->ddp[i] = ddf * d[i];
        for (int j = 0; j < 3; j++)
            c->rotation[i][j] = rz[i][0] * r0[0][j] + rz[i][1] * r0[1][j] + rz[i][2] * r0[2][j];
        c->w[i] = 0.0;
        c->dw[i] = 0.0;
    }
    c->w[2] = df * yaw;
    c->dw[2] = ddf * yaw;
}

/* The wrench the tool exerts on the table (pressing down: f_z < 0). */
static void table(double z_table, const double p[3], const double dp[3], double wrench[6]) {
    const double depth = z_table - p[2];
    double push = 0.0;
    if (depth > 0.0) {
        push = KE * depth - BE * dp[2];
        if (push < 0.0) push = 0.0;
    }
    for (int i = 0; i < 6; i++) wrench[i] = 0.0;
    wrench[2] = -push;
}

/* J_v q' (m/s). */
static void tip_velocity(const AdaptimpTip *t, const double dq[N], double dp[3]) {
    for (int i = 0; i < 3; i++) {
        dp[i] = 0.0;
        for (int j = 0; j < N; j++) dp[i] += t->jacobian[i][j] * dq[j];
    }
}

/* The rotation angle of a b^T (rad). */
static double angle_between(double a[3][3], double b[3][3]) {
    double r[3][3];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) r[i][j] = a[i][0] * b[j][0] + a[i][1] * b[j][1] + a[i][2] * b[j][2];
    const double x = r[2][1] - r[1][2], y = r[0][2] - r[2][0], z = r[1][0] - r[0][1];
    return atan2(sqrt(x * x + y * y + z * z), r[0][0] + r[1][1] + r[2][2] - 1.0);
}

/* The Cartesian controller: the outer loop with the schema's defaults (6-D),
 * the robot scenario's state feedback (hardened) with centres along the joint
 * orbit of the commanded motion, and gains matched to the inertias. */
static int controller(const AdaptimpChain *chain, const double p0[3], double r0[3][3],
                      AdaptimpCartesian **out) {
    enum { STEPS = 1500, NODES = 32 };
    AdaptimpCartesianParams cart;
    AdaptimpParams joint;
    static AdaptimpPoseTarget path[STEPS];
    static double centers[NODES * 4 * N], widths2[4 * N];
    const double tube[2] = {0.05, 0.2};
    size_t nodes = 0;
    for (int k = 0; k < STEPS; k++) target(p0, r0, k * TS, &path[k]);
    if (!check(adaptimp_cartesian_params_default(&cart), "Cartesian parameters") ||
        !check(adaptimp_cartesian_orbit_centres(chain, &cart, TS, N, HOME, path, STEPS, NODES,
                                                tube, centers, widths2, &nodes),
               "orbit centres") ||
        !check(adaptimp_params_default(&joint, N, ADAPTIMP_LAW_STATE_FEEDBACK,
                                       ADAPTIMP_PRESET_ROBOT),
               "joint parameters"))
        return 0;
    joint.ts = TS;
    joint.impedance = ADAPTIMP_IMPEDANCE_EXTERNAL;
    for (int i = 0; i < N; i++) {
        joint.tau_max[i] = TAU_MAX[i];
        joint.kp[i] = 0.25 * INERTIA[i] / TS;
        joint.kzeta[i] = (1.0 + joint.kp[i] * joint.kp[i]) / 2.0 + 10.0;
        joint.k1[i] = 20.0;
    }
    for (int i = 0; i < 3; i++) joint.gamma[i] = 1.0;
    /* |W_D|, |W_C|, |W_G| <= |tau_max|/sqrt(L) over 10 rad/s^2, 1 rad/s, 1 (L = 32), rounded. */
    joint.weight_bound_mode = ADAPTIMP_WEIGHT_BOUND_FIXED;
    joint.weight_bound[0] = 3.1;
    joint.weight_bound[1] = 31.0;
    joint.weight_bound[2] = 31.0;
    joint.centers = centers;
    joint.nodes = nodes;
    joint.widths2 = widths2;
    return check(adaptimp_cartesian_new(chain, &cart, &joint, out), "Cartesian controller");
}

static int run(double t_final) {
    AdaptimpChain *chain = NULL;
    AdaptimpCartesian *cart = NULL;
    AdaptimpCartesianState *st = NULL;
    AdaptimpTip at;
    int ok = check(panda(&chain), "chain") &&
             check(adaptimp_chain_tip(chain, N, HOME, NULL, &at), "tip");
    double p0[3], r0[3][3];
    memcpy(p0, at.position, sizeof p0);
    memcpy(r0, at.rotation, sizeof r0);
    ok = ok && controller(chain, p0, r0, &cart) &&
         check(adaptimp_cartesian_state_new(cart, N, HOME, &st), "state");
    const double z_table = p0[2] - BELOW;
    AdaptimpCartesianParams defaults;
    ok = ok && check(adaptimp_cartesian_params_default(&defaults), "Cartesian parameters");
    const double kd = defaults.kd[2];
    double q[N], dq[N] = {0}, wrench[6] = {0}, worst_p = 0.0, worst_r = 0.0, peak = 0.0;
    memcpy(q, HOME, sizeof q);
    AdaptimpPoseTarget c;
    AdaptimpCartesianCommand cmd;
    const long steps = lround(t_final / TS);
    for (long k = 0; ok && k < steps; k++) {
        const double t = k * TS;
        double dp[3];
        ok = check(adaptimp_chain_tip(chain, N, q, dq, &at), "tip");
        tip_velocity(&at, dq, dp);
        table(z_table, at.position, dp, wrench);
        target(p0, r0, t, &c);
        ok = ok && check(adaptimp_cartesian_step(cart, st, N, q, dq, wrench, &c, &cmd), "step");
        if (!ok) break;
        if (t >= 0.2 && t < 0.6) {
            /* In free motion, before the table: the tool against the command. */
            double e = 0.0;
            for (int i = 0; i < 3; i++) e += (at.position[i] - c.p[i]) * (at.position[i] - c.p[i]);
            worst_p = fmax(worst_p, sqrt(e));
            worst_r = fmax(worst_r, angle_between(c.rotation, at.rotation));
        }
        double tau[N];
        for (int i = 0; i < N; i++) {
            tau[i] = cmd.tau_sat[i];
            peak = fmax(peak, fabs(tau[i]) / TAU_MAX[i]);
        }
        /* The plant: 10 semi-implicit Euler substeps, tau held, the contact recomputed. */
        const double h = TS / 10.0;
        for (int sub = 0; ok && sub < 10; sub++) {
            double f[6], v[3];
            ok = check(adaptimp_chain_tip(chain, N, q, dq, &at), "tip");
            tip_velocity(&at, dq, v);
            table(z_table, at.position, v, f);
            for (int j = 0; j < N; j++) {
                double jtf = 0.0;
                for (int i = 0; i < 6; i++) jtf += at.jacobian[i][j] * f[i];
                dq[j] += h * ((tau[j] - jtf) / INERTIA[j]);
                q[j] += h * dq[j];
            }
        }
    }
    if (ok) {
        const double depth = z_table - c.p[2];
        const double e = cmd.p[2] - cmd.p_d[2];
        const double series = kd * KE / (kd + KE);
        printf("Panda (7 joints), 6-D Cartesian impedance, state feedback, Ts = 1 ms, t = %g s\n",
               t_final);
        printf("  moving (0.2 s ≤ t < 0.6 s): |p − p_c| ≤ %.3f mm, |e_o| ≤ %.3f mrad\n",
               worst_p * 1e3, worst_r * 1e3);
        printf("  normal force on the table       = %.3f N\n", -wrench[2]);
        printf("  target impedance K_d (p_c − p_d)_z = %.3f N\n", -kd * (c.p[2] - cmd.p_d[2]));
        printf("  (16.1): K_d k_e/(K_d + k_e)(δ_c + n·e) = %.3f N (δ_c = %.1f mm, "
               "n·e = %.4f mm)\n",
               series * (depth - e), depth * 1e3, -e * 1e3);
        printf("  orientation error |Log(R_c Rᵀ)| = %.3f mrad; peak |τ_i|/τmax_i = "
               "%.3f\n",
               angle_between(c.rotation, cmd.rotation) * 1e3, peak);
    }
    adaptimp_cartesian_state_free(st);
    adaptimp_cartesian_free(cart);
    adaptimp_chain_free(chain);
    return ok ? 0 : 1;
}

/* Bad input gets a status and a message naming it, and changes nothing. */
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
#define REQUIRE(cond)                                                                        \
    do {                                                                                     \
        if (!(cond)) {                                                                       \
            fprintf(stderr, "FAILED: %s\n", #cond);                                          \
            failures++;                                                                      \
        }                                                                                    \
    } while (0)
    AdaptimpChain *chain = NULL, *bad = NULL;
    AdaptimpCartesian *cart = NULL;
    AdaptimpCartesianState *st = NULL;
    AdaptimpJoint j[8];
    memset(j, 0, sizeof j);
    const double zero[3] = {0.0, 0.0, 0.0};
    for (int i = 0; i < 8; i++) {
        const double xyz[3] = {0.0, 0.0, 0.1};
        j[i].kind = ADAPTIMP_JOINT_KIND_REVOLUTE;
        j[i].axis[2] = 1.0;
        adaptimp_transform_xyz_rpy(xyz, zero, &j[i].origin);
    }
    /* n > 7, a zero axis, a skewed origin, a kind that is not one. */
    EXPECT(adaptimp_chain_new(j, 8, NULL, &bad), ADAPTIMP_STATUS_BAD_SIZE,
           "1 ≤ n ≤ 7 movable joints");
    j[2].axis[2] = 0.0;
    EXPECT(adaptimp_chain_new(j, 3, NULL, &bad), ADAPTIMP_STATUS_INVALID_CONFIG,
           "‖axis‖ > 0 (a movable joint needs an axis) is violated: joint axis[2] = 0");
    j[2].axis[2] = 1.0;
    j[1].origin.rotation[0][1] = 0.1;
    EXPECT(adaptimp_chain_new(j, 3, NULL, &bad), ADAPTIMP_STATUS_INVALID_CONFIG, "orthonormal");
    j[1].origin.rotation[0][1] = 0.0;
    j[0].kind = (AdaptimpJointKind)1;
    EXPECT(adaptimp_chain_new(j, 3, NULL, &bad), ADAPTIMP_STATUS_INVALID_CONFIG,
           "joints[0].kind = 1 is not an AdaptimpJointKind");
    REQUIRE(bad == NULL);
    const double lastrow[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 1, 1};
    AdaptimpTransform tf;
    EXPECT(adaptimp_transform_matrix(lastrow, &tf), ADAPTIMP_STATUS_INVALID_CONFIG,
           "last row of a homogeneous transform");
    /* A controller on the Panda. */
    AdaptimpTip at;
    EXPECT(panda(&chain), ADAPTIMP_STATUS_OK, "");
    EXPECT(adaptimp_chain_tip(chain, N, HOME, NULL, &at), ADAPTIMP_STATUS_OK, "");
    double p0[3], r0[3][3];
    memcpy(p0, at.position, sizeof p0);
    memcpy(r0, at.rotation, sizeof r0);
    REQUIRE(controller(chain, p0, r0, &cart));
    EXPECT(adaptimp_cartesian_state_new(cart, 6, HOME, &st), ADAPTIMP_STATUS_BAD_SIZE,
           "n = 6, but the Cartesian controller has 7 joints");
    EXPECT(adaptimp_cartesian_state_new(cart, N, HOME, &st), ADAPTIMP_STATUS_OK, "");
    AdaptimpPoseTarget c;
    AdaptimpCartesianCommand cmd;
    double dq[N] = {0}, wrench[6] = {0}, applied[N];
    target(p0, r0, 0.0, &c);
    EXPECT(adaptimp_cartesian_step(cart, st, N, HOME, dq, wrench, &c, &cmd), ADAPTIMP_STATUS_OK,
           "");
    /* A rotation that is not one: refused, the fallback (the torque held) applied, nothing
       else changed. */
    AdaptimpPoseTarget skew = c;
    skew.rotation[0][1] += 0.01;
    cmd.n = 99;
    EXPECT(adaptimp_cartesian_step(cart, st, N, HOME, dq, wrench, &skew, &cmd),
           ADAPTIMP_STATUS_INVALID_INPUT, "R_c");
    REQUIRE(cmd.n == N && adaptimp_cartesian_state_steps(st) == 1);
    REQUIRE(adaptimp_cartesian_state_fault(st, NULL));
    EXPECT(adaptimp_cartesian_state_applied(st, N, applied), ADAPTIMP_STATUS_OK, "");
    for (int i = 0; i < N; i++) REQUIRE(cmd.tau_sat[i] == applied[i]);
    const double not_unit[4] = {1.0, 0.1, 0.0, 0.0};
    EXPECT(adaptimp_pose_target_set_quaternion(&skew, not_unit), ADAPTIMP_STATUS_INVALID_INPUT,
           "‖q‖ = 1");
    /* Wrong sizes and NULLs: refused, the fallback written, the refusal recorded. */
    EXPECT(adaptimp_cartesian_step(cart, st, 6, HOME, dq, wrench, &c, &cmd),
           ADAPTIMP_STATUS_BAD_SIZE, "n = 6");
    REQUIRE(cmd.n == N);
    EXPECT(adaptimp_cartesian_step(cart, st, N, HOME, dq, NULL, &c, &cmd),
           ADAPTIMP_STATUS_NULL_POINTER, "wrench is NULL");
    EXPECT(adaptimp_cartesian_step(cart, NULL, N, HOME, dq, wrench, &c, &cmd),
           ADAPTIMP_STATUS_NULL_POINTER, "state is NULL");
    REQUIRE(cmd.n == 0 && cmd.tau_sat[0] == 0.0);
    wrench[3] = NAN;
    EXPECT(adaptimp_cartesian_step(cart, st, N, HOME, dq, wrench, &c, &cmd),
           ADAPTIMP_STATUS_NON_FINITE, "wrench[3] is not finite");
    wrench[3] = 0.0;
    EXPECT(adaptimp_cartesian_state_clear_fault(st), ADAPTIMP_STATUS_OK, "");
    target(p0, r0, TS, &c);
    EXPECT(adaptimp_cartesian_step(cart, st, N, HOME, dq, wrench, &c, &cmd), ADAPTIMP_STATUS_OK,
           "");
    REQUIRE(adaptimp_cartesian_state_steps(st) == 2);
    const double kd[3] = {-1.0, 500.0, 500.0}, kd_rot[3] = {20.0, 20.0, 20.0};
    EXPECT(adaptimp_cartesian_set_stiffness(cart, st, kd, kd_rot), ADAPTIMP_STATUS_INVALID_CONFIG,
           "Kd ≥ 0");
    adaptimp_cartesian_state_free(st);
    /* A state in a buffer of ours (no allocation by the library): after free,
       the buffer is ours again and the handle is refused. */
    size_t size = 0, align = 0;
    EXPECT(adaptimp_cartesian_state_buffer_size(cart, &size, &align), ADAPTIMP_STATUS_OK, "");
    void *buf = aligned_alloc(align, (size + align - 1) / align * align);
    EXPECT(adaptimp_cartesian_state_init(cart, N, HOME, buf, size - 8, &st),
           ADAPTIMP_STATUS_BAD_SIZE, "needs");
    EXPECT(adaptimp_cartesian_state_init(cart, N, HOME, buf, size, &st), ADAPTIMP_STATUS_OK, "");
    target(p0, r0, 0.0, &c);
    EXPECT(adaptimp_cartesian_step(cart, st, N, HOME, dq, wrench, &c, &cmd), ADAPTIMP_STATUS_OK,
           "");
    adaptimp_cartesian_state_free(st);
    EXPECT(adaptimp_cartesian_state_clear_fault(st), ADAPTIMP_STATUS_BAD_HANDLE,
           "not a live AdaptimpCartesianState");
    free(buf);
    adaptimp_cartesian_free(cart);
    adaptimp_chain_free(chain);
    printf("%d failed\n", failures);
    return failures != 0;
}

int main(int argc, char **argv) {
    double t_final = 2.0;
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--T") == 0 && i + 1 < argc) {
            t_final = atof(argv[++i]);
        } else if (strcmp(argv[i], "--abi-checks") == 0) {
            return abi_checks();
        } else {
            fprintf(stderr, "usage: %s [--T seconds | --abi-checks]\n", argv[0]);
            return 2;
        }
    }
    return run(t_final);
}
