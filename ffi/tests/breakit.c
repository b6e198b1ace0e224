/* A break-it probe of adaptimp's C ABI, the counterpart of scripts/breakit.py:
 * parameter structs (every enum field an arbitrary integer, every real NaN,
 * infinite, huge, subnormal, negative), measurements and setpoints, NULL
 * pointers and wrong sizes, snapshots (every bit position flipped,
 * truncations, another controller's), dead and foreign handles, caller
 * buffers, chains from bad joint data, Cartesian targets that are not
 * rotations. Every case is classified:
 *
 * - accepted: it succeeded and every invariant checked held (a finite torque
 *   within tau_max, the output written, the state advanced);
 * - clear: refused with a status other than INTERNAL and a message, the
 *   output written as the header's table says, nothing changed that must
 *   not (the state's snapshot but for the refusal record, the step count);
 * - crash: a caught panic (INTERNAL), or the category's process died (a
 *   signal, or valgrind's error exit);
 * - hang: the category's process ran past its time limit;
 * - wrong: it succeeded where it must not, or an invariant failed (a torque
 *   beyond tau_max or not finite, an output not written, a state changed by
 *   a refusal, a controller that never steps again);
 * - false refusal: refused where it must succeed.
 *
 *   breakit            the table (markdown), and notes on any case not clean
 *   BREAKIT_VERBOSE=1 breakit   also every case, its status and message, on stderr
 *
 * Each category runs in its own process (fork), so a crash or a hang of one
 * is counted and the others still run. Deterministic: no randomness.
 */
#define _POSIX_C_SOURCE 200809L

#include "adaptimp.h"

#include <math.h>
#include <float.h>
#include <signal.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <fcntl.h>
#include <sys/mman.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

enum { ACCEPT, REFUSE, EITHER };
enum { CATEGORY_SECONDS = 300 };

typedef struct {
    char name[32];
    long cases, accepted, clear, crash, hang, wrong, false_refusal;
    int notes;
    char note[6][240];
} Tally;

static Tally T;

static void note(const char *fmt, const char *what, const char *detail) {
    if (T.notes < 6) {
        snprintf(T.note[T.notes], sizeof T.note[0], fmt, what, detail);
        T.notes++;
    }
}

/* Classify one case: its status, whether the invariants held, what was expected. */
static void outcome(const char *what, int expect, AdaptimpStatus s, int invariants) {
    T.cases++;
    if (getenv("BREAKIT_VERBOSE")) /* every case: what, its status, the message */
        fprintf(stderr, "%s: status %d%s%s\n", what, (int)s, s ? ": " : "",
                s ? adaptimp_last_error() : "");
    if (s == ADAPTIMP_STATUS_INTERNAL) {
        T.crash++;
        note("%s: INTERNAL (%s)", what, adaptimp_last_error());
    } else if (s == ADAPTIMP_STATUS_OK) {
        if (!invariants) {
            T.wrong++;
            note("%s: accepted, an invariant failed%s", what, "");
        } else if (expect == REFUSE) {
            T.wrong++;
            note("%s: accepted where it must be refused%s", what, "");
        } else {
            T.accepted++;
        }
    } else if (!invariants) {
        T.wrong++;
        note("%s: refused (%s), but an invariant failed", what, adaptimp_last_error());
    } else if (adaptimp_last_error()[0] == '\0') {
        T.wrong++;
        note("%s: refused without a message%s", what, "");
    } else if (expect == ACCEPT) {
        T.false_refusal++;
        note("%s: refused (%s)", what, adaptimp_last_error());
    } else {
        T.clear++;
    }
}

/* ---- Values. ---- */

static const double BAD[] = {NAN,  INFINITY, -INFINITY, 1e300, -1e300, 1e151, 1e99, 1e50,
                             1e-320, -0.0, 0.0,      -1.0,      2e6,   1e9,    1.5e9};
enum { NBAD = sizeof BAD / sizeof BAD[0] };

static const unsigned RAW[] = {0u,   1u,   2u,   7u,   9u,   99u,   100u,  101u, 102u,
                               103u, 200u, 201u, 300u, 403u, 702u,  1001u, 1102u, 1201u,
                               1302u, 1303u, 1400u, 1401u, 1402u, 65535u, 0x7fffffffu,
                               0xffffffffu};
enum { NRAW = sizeof RAW / sizeof RAW[0] };

static int finite_all(const double *v, size_t n) {
    for (size_t i = 0; i < n; i++)
        if (!isfinite(v[i])) return 0;
    return 1;
}

/* ---- Controllers. ---- */

static AdaptimpParams robot(AdaptimpLaw law) {
    AdaptimpParams p;
    if (adaptimp_params_default(&p, 2, law, ADAPTIMP_PRESET_ROBOT) != ADAPTIMP_STATUS_OK) abort();
    return p;
}

typedef struct {
    AdaptimpController *ctrl;
    AdaptimpState *state;
    double tau_max[2];
} Loop;

static int open_loop(const AdaptimpParams *p, Loop *l) {
    l->ctrl = NULL;
    l->state = NULL;
    l->tau_max[0] = p->tau_max[0];
    l->tau_max[1] = p->tau_max[1];
    if (adaptimp_controller_new(p, &l->ctrl) != ADAPTIMP_STATUS_OK) return 0;
    if (adaptimp_state_new(l->ctrl, &l->state) != ADAPTIMP_STATUS_OK) abort();
    return 1;
}

static void close_loop(Loop *l) {
    adaptimp_state_free(l->state);
    adaptimp_controller_free(l->ctrl);
}

static void inputs(long k, double q[2], double dq[2], double te[2]) {
    const double s = (double)k;
    q[0] = 0.25 + 0.01 * sin(0.1 * s);
    q[1] = -0.05 + 0.01 * cos(0.07 * s);
    dq[0] = 0.1 * cos(0.1 * s);
    dq[1] = -0.1 * sin(0.07 * s);
    te[0] = fmax(0.0, 5.0 * sin(0.05 * s));
    te[1] = 0.0;
}

/* An accepted step's invariants: n written, a finite torque within tau_max. */
static int torque_ok(const Loop *l, const AdaptimpCommand *c) {
    if (c->n != 2 || !finite_all(c->tau_sat, 2)) return 0;
    for (int i = 0; i < 2; i++)
        if (fabs(c->tau_sat[i]) > l->tau_max[i]) return 0;
    return 1;
}

/* A good step at k; its status. */
static AdaptimpStatus good_step(Loop *l, long k, AdaptimpCommand *c) {
    double q[2], dq[2], te[2];
    inputs(k, q, dq, te);
    return adaptimp_step(l->ctrl, l->state, 2, q, dq, te, NULL, c);
}

/* The state's snapshot (heap). */
static double *snapshot(const AdaptimpState *s, size_t *len) {
    *len = adaptimp_state_snapshot_len(s);
    double *b = malloc(*len * sizeof *b);
    if (!b || adaptimp_state_save(s, b, *len, NULL) != ADAPTIMP_STATUS_OK) abort();
    return b;
}

/* The same but for a refusal's record: the applied torque, the last measured
   position (the last 2n values before the checksum) and the checksum. */
static int same_but_refusal(const double *a, const double *b, size_t len) {
    return memcmp(a, b, (len - 5) * sizeof *a) == 0;
}

/* One bad step on a warmed-up loop: refused or accepted as expected; a
   refusal writes the fallback (= the applied torque), records the fault,
   changes nothing else; the next good step is accepted (not bricked). */
static void bad_step(const AdaptimpParams *p, const char *what, int expect, size_t n,
                     const double *q, const double *dq, const double *te,
                     const AdaptimpSetpoint *sp, int null_out) {
    Loop l;
    if (!open_loop(p, &l)) abort();
    AdaptimpCommand c;
    for (long k = 0; k < 5; k++)
        if (good_step(&l, k, &c) != ADAPTIMP_STATUS_OK) abort();
    size_t len;
    double *before = snapshot(l.state, &len);
    memset(&c, 0xAB, sizeof c);
    AdaptimpStatus s = adaptimp_step(l.ctrl, l.state, n, q, dq, te, sp, null_out ? NULL : &c);
    const char *msg = adaptimp_last_error();
    char saved[512];
    snprintf(saved, sizeof saved, "%s", msg);
    int ok = 1;
    if (s == ADAPTIMP_STATUS_OK) {
        ok = torque_ok(&l, &c) && adaptimp_state_steps(l.state) == 6;
    } else {
        double applied[2];
        size_t len2;
        double *after = snapshot(l.state, &len2);
        ok = ok && adaptimp_state_steps(l.state) == 5 && same_but_refusal(before, after, len);
        ok = ok && adaptimp_state_fault(l.state, NULL);
        ok = ok && adaptimp_state_applied(l.state, 2, applied) == ADAPTIMP_STATUS_OK;
        if (!null_out)
            ok = ok && c.n == 2 && c.tau_sat[0] == applied[0] && c.tau_sat[1] == applied[1] &&
                 fabs(applied[0]) <= l.tau_max[0] && fabs(applied[1]) <= l.tau_max[1];
        free(after);
    }
    /* Not bricked: the next good step is accepted (report policy). */
    AdaptimpCommand next;
    ok = ok && good_step(&l, 6, &next) == ADAPTIMP_STATUS_OK && torque_ok(&l, &next);
    free(before);
    close_loop(&l);
    /* The message of the bad call, for the classification. */
    if (s != ADAPTIMP_STATUS_OK && saved[0] == '\0') s = (AdaptimpStatus)ADAPTIMP_STATUS_INTERNAL;
    outcome(what, expect, s, ok);
}

/* ---- Categories. ---- */

static void construction(void) {
    const AdaptimpLaw laws[3] = {ADAPTIMP_LAW_PD, ADAPTIMP_LAW_STATE_FEEDBACK,
                                 ADAPTIMP_LAW_OUTPUT_FEEDBACK};
    char what[160];
    /* Every enum field: every integer of RAW; valid only when in its enum. */
    for (int f = 0; f < 12; f++) {
        static const char *names[12] = {"law",          "aux_law",       "robust",
                                        "learning_step", "saturation_learning",
                                        "weight_bound_mode", "observer_init", "observer_hold",
                                        "impedance",    "fallback",      "fault_policy",
                                        "conditions"};
        static const unsigned base[12] = {100,  300,  400,  500,  600,  700,
                                          800,  900,  1000, 1100, 1200, 1400};
        static const unsigned count[12] = {3, 3, 4, 2, 2, 3, 2, 2, 2, 3, 2, 2};
        for (int r = 0; r < NRAW; r++) {
            AdaptimpParams p = robot(ADAPTIMP_LAW_STATE_FEEDBACK);
            unsigned v = RAW[r];
            /* Written as the integer a C caller may put in the field. */
            switch (f) {
            case 0: memcpy(&p.law, &v, sizeof v); break;
            case 1: memcpy(&p.aux_law, &v, sizeof v); break;
            case 2: memcpy(&p.robust, &v, sizeof v); break;
            case 3: memcpy(&p.learning_step, &v, sizeof v); break;
            case 4: memcpy(&p.saturation_learning, &v, sizeof v); break;
            case 5: memcpy(&p.weight_bound_mode, &v, sizeof v); break;
            case 6: memcpy(&p.observer_init, &v, sizeof v); break;
            case 7: memcpy(&p.observer_hold, &v, sizeof v); break;
            case 8: memcpy(&p.impedance, &v, sizeof v); break;
            case 9: memcpy(&p.fallback, &v, sizeof v); break;
            case 10: memcpy(&p.fault_policy, &v, sizeof v); break;
            default: memcpy(&p.conditions, &v, sizeof v); break;
            }
            const int valid = v >= base[f] && v < base[f] + count[f];
            snprintf(what, sizeof what, "params.%s = %u", names[f], v);
            Loop l;
            AdaptimpStatus s = adaptimp_controller_new(&p, &l.ctrl);
            int ok = 1;
            if (s == ADAPTIMP_STATUS_OK) {
                if (adaptimp_state_new(l.ctrl, &l.state) != ADAPTIMP_STATUS_OK) abort();
                l.tau_max[0] = p.tau_max[0];
                l.tau_max[1] = p.tau_max[1];
                AdaptimpCommand c;
                for (long k = 0; ok && k < 20; k++) {
                    AdaptimpStatus st = good_step(&l, k, &c);
                    ok = (st == ADAPTIMP_STATUS_OK && torque_ok(&l, &c)) ||
                         (st != ADAPTIMP_STATUS_INTERNAL && c.n == 2 && finite_all(c.tau_sat, 2));
                }
                close_loop(&l);
            } else {
                ok = s == ADAPTIMP_STATUS_INVALID_CONFIG &&
                     strstr(adaptimp_last_error(), names[f]) != NULL;
            }
            outcome(what, valid ? EITHER : REFUSE, s, ok);
        }
    }
    /* Every real field: every value of BAD on each law; accepted only if the
       controller then steps with finite torques within its limits. */
    for (int law = 0; law < 3; law++) {
        for (int f = 0; f < 24; f++) {
            for (int b = 0; b < NBAD; b++) {
                AdaptimpParams p = robot(laws[law]);
                double v = BAD[b];
                double *field;
                switch (f) {
                case 0: field = &p.ts; break;
                case 1: field = &p.k1[0]; break;
                case 2: field = &p.kp[1]; break;
                case 3: field = &p.kzeta[0]; break;
                case 4: field = &p.mu; break;
                case 5: field = &p.kr[0]; break;
                case 6: field = &p.phi; break;
                case 7: field = &p.kappa; break;
                case 8: field = &p.gamma[0]; break;
                case 9: field = &p.sigma[2]; break;
                case 10: field = &p.eps; break;
                case 11: field = &p.lam1[1]; break;
                case 12: field = &p.tau_max[0]; break;
                case 13: field = &p.dd[0]; break;
                case 14: field = &p.cd[1]; break;
                case 15: field = &p.gd[0]; break;
                case 16: field = &p.eta2; break;
                case 17: field = &p.xc_offset[0]; break;
                case 18: field = &p.xc_omega[1]; break;
                case 19: field = &p.fallback_damping[0]; break;
                case 20: field = &p.q_max[0]; break;
                case 21: field = &p.q_jump_max[1]; break;
                case 22: field = &p.tau_rate_max[0]; break;
                default: field = &p.weight_bound[0]; p.weight_bound_mode = ADAPTIMP_WEIGHT_BOUND_FIXED; break;
                }
                *field = v;
                snprintf(what, sizeof what, "law %d, real field %d = %g", law, f, v);
                Loop l = {NULL, NULL, {p.tau_max[0], p.tau_max[1]}};
                AdaptimpStatus s = adaptimp_controller_new(&p, &l.ctrl);
                int ok = (s == ADAPTIMP_STATUS_OK) == (l.ctrl != NULL);
                if (s == ADAPTIMP_STATUS_OK) {
                    if (adaptimp_state_new(l.ctrl, &l.state) != ADAPTIMP_STATUS_OK) abort();
                    AdaptimpCommand c;
                    for (long k = 0; ok && k < 50; k++) {
                        AdaptimpStatus st = good_step(&l, k, &c);
                        /* A refusal is fine (a limit of 0 refuses everything);
                           a torque is finite and within tau_max. */
                        ok = st != ADAPTIMP_STATUS_INTERNAL && c.n == 2 &&
                             finite_all(c.tau_sat, 2) &&
                             fabs(c.tau_sat[0]) <= fabs(l.tau_max[0]) &&
                             fabs(c.tau_sat[1]) <= fabs(l.tau_max[1]);
                    }
                    close_loop(&l);
                }
                outcome(what, isnan(v) ? REFUSE : EITHER, s, ok);
            }
        }
    }
    /* n, centres, widths, the preset's enum arguments in every order. */
    const size_t ns[] = {0, 8, 100, SIZE_MAX};
    for (size_t i = 0; i < sizeof ns / sizeof ns[0]; i++) {
        /* A byte pattern (padding included), so "unchanged" compares no
           uninitialised byte. */
        AdaptimpParams p, q;
        memset(&p, 0xab, sizeof p);
        memset(&q, 0xab, sizeof q);
        snprintf(what, sizeof what, "n = %zu", ns[i]);
        AdaptimpStatus s = adaptimp_params_default(&p, ns[i], ADAPTIMP_LAW_PD, ADAPTIMP_PRESET_ROBOT);
        outcome(what, REFUSE, s, s == ADAPTIMP_STATUS_BAD_SIZE && memcmp(&p, &q, sizeof p) == 0);
        p = robot(ADAPTIMP_LAW_PD);
        p.n = ns[i];
        AdaptimpController *c = NULL;
        s = adaptimp_controller_new(&p, &c);
        outcome(what, REFUSE, s, s == ADAPTIMP_STATUS_BAD_SIZE && c == NULL);
    }
    for (int a = 0; a < NRAW; a++) {
        for (int b = 0; b < NRAW; b++) {
            AdaptimpController *c = NULL;
            unsigned pa = RAW[a], lb = RAW[b];
            AdaptimpPreset preset;
            AdaptimpLaw law;
            memcpy(&preset, &pa, sizeof pa);
            memcpy(&law, &lb, sizeof lb);
            const int valid = pa >= 200 && pa <= 201 && lb >= 100 && lb <= 102;
            snprintf(what, sizeof what, "new_preset(%u, %u)", pa, lb);
            AdaptimpStatus s = adaptimp_controller_new_preset(preset, law, &c);
            outcome(what, valid ? ACCEPT : REFUSE, s, (s == ADAPTIMP_STATUS_OK) == (c != NULL));
            adaptimp_controller_free(c);
        }
    }
    {
        AdaptimpParams z;
        memset(&z, 0, sizeof z);
        z.n = 2;
        AdaptimpController *c = NULL;
        AdaptimpStatus s = adaptimp_controller_new(&z, &c);
        outcome("a zeroed AdaptimpParams", REFUSE, s, c == NULL);
    }
    double centres[8 * 4 * 2], widths[8];
    for (int i = 0; i < 8 * 4 * 2; i++) centres[i] = 0.1 * (i % 7) - 0.3;
    for (int b = 0; b < NBAD; b++) {
        AdaptimpParams p = robot(ADAPTIMP_LAW_STATE_FEEDBACK);
        for (int i = 0; i < 8; i++) widths[i] = 1.0;
        widths[3] = BAD[b];
        p.centers = centres;
        p.nodes = 8;
        p.widths2 = widths;
        snprintf(what, sizeof what, "widths2[3] = %g", BAD[b]);
        Loop l = {NULL, NULL, {p.tau_max[0], p.tau_max[1]}};
        AdaptimpStatus s = adaptimp_controller_new(&p, &l.ctrl);
        int ok = (s == ADAPTIMP_STATUS_OK) == (l.ctrl != NULL);
        if (s == ADAPTIMP_STATUS_OK) {
            if (adaptimp_state_new(l.ctrl, &l.state) != ADAPTIMP_STATUS_OK) abort();
            AdaptimpCommand c;
            for (long k = 0; ok && k < 20; k++) {
                AdaptimpStatus st = good_step(&l, k, &c);
                ok = st != ADAPTIMP_STATUS_INTERNAL && c.n == 2 && finite_all(c.tau_sat, 2);
            }
            close_loop(&l);
        }
        outcome(what, isnan(BAD[b]) ? REFUSE : EITHER, s, ok);
    }
    {
        AdaptimpParams p = robot(ADAPTIMP_LAW_STATE_FEEDBACK);
        p.centers = centres;
        p.nodes = 0;
        AdaptimpController *c = NULL;
        AdaptimpStatus s = adaptimp_controller_new(&p, &c);
        outcome("centres with nodes = 0", REFUSE, s, c == NULL);
        p.nodes = SIZE_MAX / 4;
        p.centers = NULL;
        s = adaptimp_controller_new(&p, &c);
        outcome("NULL centres with nodes = SIZE_MAX/4 (the grid)", EITHER, s, 1);
        adaptimp_controller_free(c);
        c = NULL;
        p.centers = centres;
        p.nodes = SIZE_MAX / 2;
        s = adaptimp_controller_new(&p, &c);
        outcome("nodes × 4n overflows", REFUSE, s, c == NULL);
    }
}

static void steps(void) {
    const AdaptimpLaw laws[3] = {ADAPTIMP_LAW_PD, ADAPTIMP_LAW_STATE_FEEDBACK,
                                 ADAPTIMP_LAW_OUTPUT_FEEDBACK};
    char what[160];
    for (int law = 0; law < 3; law++) {
        AdaptimpParams p = robot(laws[law]);
        /* Every input entry with every bad value. */
        for (int which = 0; which < 3; which++) {
            for (int i = 0; i < 2; i++) {
                for (int b = 0; b < NBAD; b++) {
                    double q[2], dq[2], te[2];
                    inputs(5, q, dq, te);
                    double *v = which == 0 ? q : which == 1 ? dq : te;
                    v[i] = BAD[b];
                    /* Output feedback does not read dq. */
                    const int matters = !(which == 1 && law == 2);
                    const int bad = !isfinite(BAD[b]) || fabs(BAD[b]) > (which == 2 ? 1e9 : 1e6);
                    snprintf(what, sizeof what, "law %d: %s[%d] = %g", law,
                             which == 0 ? "q" : which == 1 ? "dq" : "tau_e", i, BAD[b]);
                    bad_step(&p, what, bad && matters ? REFUSE : EITHER, 2, q, dq, te, NULL, 0);
                }
            }
        }
        /* Setpoints: every entry with every bad value (dxc = 1e99 was reported). */
        for (int part = 0; part < 3; part++) {
            for (int b = 0; b < NBAD + 1; b++) {
                double q[2], dq[2], te[2];
                inputs(5, q, dq, te);
                AdaptimpSetpoint sp;
                memset(&sp, 0, sizeof sp);
                sp.x[0] = q[0];
                sp.x[1] = q[1];
                const double v = b < NBAD ? BAD[b] : 1e99;
                double *e = part == 0 ? sp.x : part == 1 ? sp.dx : sp.ddx;
                e[b % 2] = v;
                const int bad = !isfinite(v) || fabs(v) > 1e6;
                snprintf(what, sizeof what, "law %d: setpoint %s[%d] = %g", law,
                         part == 0 ? "xc" : part == 1 ? "dxc" : "ddxc", b % 2, v);
                bad_step(&p, what, bad ? REFUSE : EITHER, 2, q, dq, te, &sp, 0);
            }
        }
        /* NULLs and sizes. */
        double q[2], dq[2], te[2];
        inputs(5, q, dq, te);
        snprintf(what, sizeof what, "law %d: q NULL", law);
        bad_step(&p, what, REFUSE, 2, NULL, dq, te, NULL, 0);
        snprintf(what, sizeof what, "law %d: tau_e NULL", law);
        bad_step(&p, what, REFUSE, 2, q, dq, NULL, NULL, 0);
        snprintf(what, sizeof what, "law %d: dq NULL", law);
        bad_step(&p, what, law == 2 ? ACCEPT : REFUSE, 2, q, NULL, te, NULL, 0);
        snprintf(what, sizeof what, "law %d: out NULL", law);
        bad_step(&p, what, REFUSE, 2, q, dq, te, NULL, 1);
        const size_t sizes[] = {0, 1, 3, 7, 8, SIZE_MAX};
        for (size_t i = 0; i < sizeof sizes / sizeof sizes[0]; i++) {
            snprintf(what, sizeof what, "law %d: n = %zu", law, sizes[i]);
            bad_step(&p, what, REFUSE, sizes[i], q, dq, te, NULL, 0);
        }
    }
    /* The fallbacks and the latch: a refusal's torque is finite and within
       tau_max, a latched fault refuses every call until cleared. */
    const AdaptimpFallback fallbacks[3] = {ADAPTIMP_FALLBACK_HOLD, ADAPTIMP_FALLBACK_ZERO,
                                           ADAPTIMP_FALLBACK_DAMPING};
    for (int f = 0; f < 3; f++) {
        for (int b = 0; b < NBAD; b++) {
            AdaptimpParams p = robot(ADAPTIMP_LAW_STATE_FEEDBACK);
            p.fallback = fallbacks[f];
            p.fallback_damping[0] = p.fallback_damping[1] = 3.0;
            p.fault_policy = ADAPTIMP_FAULT_POLICY_LATCH;
            Loop l;
            if (!open_loop(&p, &l)) abort();
            AdaptimpCommand c;
            for (long k = 0; k < 5; k++) good_step(&l, k, &c);
            double q[2], dq[2], te[2];
            inputs(5, q, dq, te);
            q[1] = NAN;
            dq[0] = BAD[b];
            AdaptimpStatus s = adaptimp_step(l.ctrl, l.state, 2, q, dq, te, NULL, &c);
            int ok = s != ADAPTIMP_STATUS_OK && c.n == 2 && finite_all(c.tau_sat, 2) &&
                     fabs(c.tau_sat[0]) <= p.tau_max[0] && fabs(c.tau_sat[1]) <= p.tau_max[1];
            for (long k = 6; k < 9; k++) {
                /* Latched: refused, the fallback written and applied (hold and
                   zero: the same torque; damping: −Kd q̇ of this call). */
                AdaptimpCommand d;
                double applied[2];
                ok = ok && good_step(&l, k, &d) == ADAPTIMP_STATUS_FAULTED &&
                     adaptimp_state_applied(l.state, 2, applied) == ADAPTIMP_STATUS_OK &&
                     d.tau_sat[0] == applied[0] && d.tau_sat[1] == applied[1] &&
                     (f == 2 || (d.tau_sat[0] == c.tau_sat[0] && d.tau_sat[1] == c.tau_sat[1]));
            }
            ok = ok && adaptimp_state_clear_fault(l.state) == ADAPTIMP_STATUS_OK &&
                 good_step(&l, 9, &c) == ADAPTIMP_STATUS_OK && torque_ok(&l, &c);
            snprintf(what, sizeof what, "fallback %d, latched, dq[0] = %g", f, BAD[b]);
            outcome(what, REFUSE, s, ok);
            close_loop(&l);
        }
    }
}

static void snapshots(void) {
    char what[160];
    AdaptimpParams p = robot(ADAPTIMP_LAW_OUTPUT_FEEDBACK);
    Loop a, b;
    if (!open_loop(&p, &a) || !open_loop(&p, &b)) abort();
    AdaptimpCommand c;
    for (long k = 0; k < 50; k++) good_step(&a, k, &c);
    size_t len, lb;
    double *snap = snapshot(a.state, &len);
    double *before = snapshot(b.state, &lb);
    /* Every position, three bits each (low mantissa, high mantissa, exponent). */
    const int bits[3] = {0, 40, 60};
    for (size_t i = 0; i < len; i++) {
        for (int j = 0; j < 3; j++) {
            double *bad = malloc(len * sizeof *bad);
            memcpy(bad, snap, len * sizeof *bad);
            uint64_t u;
            memcpy(&u, &bad[i], sizeof u);
            u ^= (uint64_t)1 << bits[j];
            memcpy(&bad[i], &u, sizeof u);
            AdaptimpStatus s = adaptimp_state_restore(b.ctrl, b.state, bad, len);
            size_t l2;
            double *after = snapshot(b.state, &l2);
            const int ok = memcmp(after, before, len * sizeof *after) == 0;
            free(after);
            free(bad);
            snprintf(what, sizeof what, "snapshot[%zu] bit %d flipped", i, bits[j]);
            outcome(what, REFUSE, s, ok);
        }
    }
    const size_t lens[] = {0, 1, 5, 100, len - 1, len + 1};
    double *longer = calloc(len + 1, sizeof *longer);
    memcpy(longer, snap, len * sizeof *snap);
    for (size_t i = 0; i < sizeof lens / sizeof lens[0]; i++) {
        AdaptimpStatus s = adaptimp_state_restore(b.ctrl, b.state, longer, lens[i]);
        size_t l2;
        double *after = snapshot(b.state, &l2);
        snprintf(what, sizeof what, "snapshot of %zu values (of %zu)", lens[i], len);
        outcome(what, REFUSE, s, memcmp(after, before, len * sizeof *after) == 0);
        free(after);
    }
    free(longer);
    /* Another controller's: smaller limits (its applied torque beyond them). */
    AdaptimpParams big = p;
    big.tau_max[0] = big.tau_max[1] = 60.0;
    Loop g;
    if (!open_loop(&big, &g)) abort();
    const double far[2] = {1.5, -1.5}, zero[2] = {0.0, 0.0};
    for (int k = 0; k < 30; k++) adaptimp_step(g.ctrl, g.state, 2, far, zero, zero, NULL, &c);
    size_t lg;
    double *gsnap = snapshot(g.state, &lg);
    AdaptimpStatus s = adaptimp_state_restore(b.ctrl, b.state, gsnap, lg);
    double *after = snapshot(b.state, &lb);
    outcome("a snapshot with |tau| > tau_max of this controller", REFUSE, s,
            memcmp(after, before, len * sizeof *after) == 0);
    free(after);
    s = adaptimp_state_restore(g.ctrl, b.state, gsnap, lg);
    outcome("the same into its own controller's state", ACCEPT, s, 1);
    s = adaptimp_state_restore(b.ctrl, b.state, snap, len);
    outcome("a good snapshot", ACCEPT, s, adaptimp_state_steps(b.state) == 50);
    s = adaptimp_state_restore(b.ctrl, b.state, NULL, len);
    outcome("restore from NULL", REFUSE, s, 1);
    s = adaptimp_state_save(b.state, NULL, len, NULL);
    outcome("save into NULL", REFUSE, s, 1);
    double small[4] = {0};
    s = adaptimp_state_save(b.state, small, 4, NULL);
    outcome("save into 4 values", REFUSE, s, small[0] == 0.0);
    free(gsnap);
    free(snap);
    free(before);
    close_loop(&g);
    close_loop(&a);
    close_loop(&b);
}

static void handles(void) {
    AdaptimpParams p = robot(ADAPTIMP_LAW_STATE_FEEDBACK);
    Loop l;
    if (!open_loop(&p, &l)) abort();
    double q[2], dq[2], te[2];
    inputs(0, q, dq, te);
    AdaptimpCommand c;
    size_t size = 0, align = 0;
    if (adaptimp_state_buffer_size(l.ctrl, &size, &align) != ADAPTIMP_STATUS_OK) abort();
    size_t padded = (size + 64 + align - 1) / align * align;
    unsigned char *buf = aligned_alloc(64, (padded + 63) / 64 * 64);
    /* Caller buffers: too small, misaligned, NULL, then one that works. */
    for (size_t off = 0; off < 8; off++) {
        for (size_t shrink = 0; shrink < 3; shrink++) {
            AdaptimpState *st = NULL;
            const size_t give = size - shrink * 8 + (shrink == 2 ? 7 : 0);
            AdaptimpStatus s = adaptimp_state_init(l.ctrl, buf + off, give, &st);
            const int fits = off % align == 0 && give >= size;
            int ok = (s == ADAPTIMP_STATUS_OK) == (st != NULL);
            if (s == ADAPTIMP_STATUS_OK) {
                ok = ok && adaptimp_step(l.ctrl, st, 2, q, dq, te, NULL, &c) == ADAPTIMP_STATUS_OK;
                adaptimp_state_free(st);
                /* The life ended: refused, not used. */
                ok = ok && adaptimp_step(l.ctrl, st, 2, q, dq, te, NULL, &c) ==
                               ADAPTIMP_STATUS_BAD_HANDLE && c.n == 0;
                adaptimp_state_free(st); /* again: ignored */
            }
            char what[96];
            snprintf(what, sizeof what, "state in a buffer at +%zu of %zu bytes", off, give);
            outcome(what, fits ? ACCEPT : REFUSE, s, ok);
        }
    }
    AdaptimpState *st = NULL;
    outcome("state_init(NULL buffer)", REFUSE, adaptimp_state_init(l.ctrl, NULL, size, &st),
            st == NULL);
    /* Foreign pointers for every handle argument. */
    uint64_t zeros[512];
    memset(zeros, 0, sizeof zeros);
    unsigned char *junk = (unsigned char *)zeros;
    void *foreign[6] = {NULL, zeros, junk + 8, junk + 1, l.ctrl, l.state};
    for (int i = 0; i < 6; i++) {
        AdaptimpController *fc = (AdaptimpController *)foreign[i];
        AdaptimpState *fs = (AdaptimpState *)foreign[i];
        char what[96];
        const int live_c = foreign[i] == l.ctrl, live_s = foreign[i] == l.state;
        double tau[2], buf2[8] = {0};
        AdaptimpState *out = NULL;
        snprintf(what, sizeof what, "foreign pointer %d as state: step", i);
        AdaptimpStatus s = adaptimp_step(l.ctrl, fs, 2, q, dq, te, NULL, &c);
        outcome(what, live_s ? ACCEPT : REFUSE, s, live_s || c.n == 0);
        snprintf(what, sizeof what, "foreign pointer %d as controller: step", i);
        s = adaptimp_step(fc, l.state, 2, q, dq, te, NULL, &c);
        outcome(what, live_c ? ACCEPT : REFUSE, s, live_c || c.n == 0);
        snprintf(what, sizeof what, "foreign pointer %d: state_new", i);
        s = adaptimp_state_new(fc, &out);
        outcome(what, live_c ? ACCEPT : REFUSE, s, (s == ADAPTIMP_STATUS_OK) == (out != NULL));
        adaptimp_state_free(out);
        snprintf(what, sizeof what, "foreign pointer %d: reset, applied, restore", i);
        AdaptimpStatus r1 = adaptimp_state_reset(fs);
        AdaptimpStatus r2 = adaptimp_state_applied(fs, 2, tau);
        AdaptimpStatus r3 = adaptimp_state_restore(fc, fs, buf2, 8);
        const int refused = r1 != ADAPTIMP_STATUS_OK && r2 != ADAPTIMP_STATUS_OK &&
                            r3 != ADAPTIMP_STATUS_OK;
        outcome(what, live_s ? EITHER : REFUSE, refused ? r3 : ADAPTIMP_STATUS_OK,
                live_s || refused);
        (void)adaptimp_state_steps(fs);
        (void)adaptimp_state_snapshot_len(fs);
        (void)adaptimp_state_fault(fs, NULL);
        (void)adaptimp_controller_joints(fc);
        (void)adaptimp_controller_period(fc);
        if (!live_s && !live_c) {
            adaptimp_state_free(fs);
            adaptimp_controller_free(fc);
        }
    }
    free(buf);
    close_loop(&l);
}

/* ---- Chains and the Cartesian controller. ---- */

static void arm(AdaptimpJoint j[4], AdaptimpTransform *tip) {
    const double zero[3] = {0, 0, 0};
    memset(j, 0, 4 * sizeof *j);
    for (int i = 0; i < 4; i++) {
        const double xyz[3] = {0.0, 0.05 * i, 0.2}, rpy[3] = {0.3 * i, -0.2, 0.1};
        j[i].kind = i == 2 ? ADAPTIMP_JOINT_KIND_FIXED
                           : (i == 1 ? ADAPTIMP_JOINT_KIND_PRISMATIC : ADAPTIMP_JOINT_KIND_REVOLUTE);
        if (adaptimp_transform_xyz_rpy(xyz, rpy, &j[i].origin) != ADAPTIMP_STATUS_OK) abort();
        j[i].axis[0] = 0.2;
        j[i].axis[2] = 1.0;
    }
    const double t[3] = {0.0, 0.0, 0.1};
    if (adaptimp_transform_xyz_rpy(t, zero, tip) != ADAPTIMP_STATUS_OK) abort();
}

static void chains(void) {
    char what[160];
    AdaptimpJoint j[4];
    AdaptimpTransform tip;
    for (int i = 0; i < 4; i++) {
        for (int f = 0; f < 16; f++) {
            for (int b = 0; b < NBAD; b++) {
                arm(j, &tip);
                double *field = f < 3 ? &j[i].origin.translation[f]
                                : f < 12 ? &j[i].origin.rotation[(f - 3) / 3][(f - 3) % 3]
                                : f < 15 ? &j[i].axis[f - 12] : &j[i].offset;
                *field = BAD[b];
                AdaptimpChain *ch = NULL;
                AdaptimpStatus s = adaptimp_chain_new(j, 4, &tip, &ch);
                int ok = (s == ADAPTIMP_STATUS_OK) == (ch != NULL);
                if (ch) {
                    AdaptimpTip t;
                    const double q[3] = {0.1, 0.05, -0.2};
                    ok = ok && adaptimp_chain_tip(ch, 3, q, q, &t) == ADAPTIMP_STATUS_OK &&
                         finite_all(t.position, 3) && finite_all(&t.rotation[0][0], 9) &&
                         finite_all(t.bias, 6);
                    adaptimp_chain_free(ch);
                }
                snprintf(what, sizeof what, "joint %d field %d = %g", i, f, BAD[b]);
                /* A fixed joint's axis and offset are not read. */
                const int read = !(i == 2 && f >= 12);
                outcome(what, isfinite(BAD[b]) || !read ? EITHER : REFUSE, s, ok);
            }
        }
        for (int r = 0; r < NRAW; r++) {
            arm(j, &tip);
            memcpy(&j[i].kind, &RAW[r], sizeof RAW[r]);
            AdaptimpChain *ch = NULL;
            AdaptimpStatus s = adaptimp_chain_new(j, 4, &tip, &ch);
            snprintf(what, sizeof what, "joint %d kind = %u", i, RAW[r]);
            const int valid = RAW[r] >= 1300 && RAW[r] <= 1302;
            outcome(what, valid ? EITHER : REFUSE, s, (s == ADAPTIMP_STATUS_OK) == (ch != NULL));
            adaptimp_chain_free(ch);
        }
    }
    /* Numbers of joints: 0 … 9 movable. */
    for (size_t count = 0; count < 10; count++) {
        AdaptimpJoint many[9];
        arm(j, &tip);
        for (size_t i = 0; i < 9; i++) many[i] = j[0];
        AdaptimpChain *ch = NULL;
        AdaptimpStatus s = adaptimp_chain_new(count ? many : NULL, count, NULL, &ch);
        snprintf(what, sizeof what, "%zu movable joints", count);
        outcome(what, count >= 1 && count <= 7 ? ACCEPT : REFUSE, s,
                (s == ADAPTIMP_STATUS_OK) == (ch != NULL));
        adaptimp_chain_free(ch);
    }
    /* Transforms from quaternions and 4 × 4 matrices. */
    for (int b = 0; b < NBAD; b++) {
        const double pos[3] = {0.0, 0.0, 0.0}, quat[4] = {BAD[b], 0.0, 0.0, 0.0};
        AdaptimpTransform t;
        AdaptimpStatus s = adaptimp_transform_pos_quat(pos, quat, &t);
        snprintf(what, sizeof what, "quaternion [%g, 0, 0, 0]", BAD[b]);
        const int good = isfinite(BAD[b]) && BAD[b] != 0.0;
        outcome(what, good ? EITHER : REFUSE, s, s != ADAPTIMP_STATUS_OK ||
                                                     finite_all(&t.rotation[0][0], 9));
        double m[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
        m[12 + b % 4] = BAD[b];
        s = adaptimp_transform_matrix(m, &t);
        snprintf(what, sizeof what, "4 × 4 last row [%d] = %g", b % 4, BAD[b]);
        const double want = b % 4 == 3 ? 1.0 : 0.0;
        outcome(what, fabs(BAD[b] - want) <= 1e-6 ? ACCEPT : REFUSE, s, 1);
    }
    /* The operational-space inertia (SPEC (23.7)) of a planar two-link arm:
       each entry of J (6 × 2) and D (2 × 2) bad in turn; a result is finite,
       a refusal leaves `out` as it was. */
    for (int e = 0; e < 16; e++) {
        for (int b = 0; b < NBAD; b++) {
            double jac[12] = {-1, -1, 1, 0, 0, 0, 0, 0, 0, 0, 1, 1}, inertia[4] = {2, 0, 0, 1};
            double *field = e < 12 ? &jac[e] : &inertia[e - 12];
            *field = BAD[b];
            double out[36];
            for (int i = 0; i < 36; i++) out[i] = 7.0;
            for (int coupled = 0; coupled < 2; coupled++) {
                AdaptimpStatus s = adaptimp_operational_inertia(2, jac, inertia, !coupled, out);
                int untouched = 1;
                for (int i = 0; i < 36; i++) untouched = untouched && out[i] == 7.0;
                const int ok = s == ADAPTIMP_STATUS_OK ? finite_all(out, 36) : untouched;
                snprintf(what, sizeof what, "operational inertia, %s[%d] = %g%s",
                         e < 12 ? "jacobian" : "inertia", e < 12 ? e : e - 12, BAD[b],
                         coupled ? ", coupled" : "");
                outcome(what, isfinite(BAD[b]) ? EITHER : REFUSE, s, ok);
                for (int i = 0; i < 36; i++) out[i] = 7.0;
            }
        }
    }
    /* Its numbers of joints and NULL pointers. */
    static const double jac9[6 * 9] = {1, 1, 1, 1, 1, 1, 1, 1, 1};
    double out[36], eye[9 * 9];
    for (size_t n = 0; n < 10; n++) {
        for (size_t i = 0; i < n * n; i++) eye[i] = i % (n + 1) == 0; /* I_n, row-major */
        AdaptimpStatus s = adaptimp_operational_inertia(n, jac9, eye, 1, out);
        snprintf(what, sizeof what, "operational inertia, n = %zu", n);
        outcome(what, n >= 1 && n <= 7 ? EITHER : REFUSE, s,
                s == ADAPTIMP_STATUS_OK ? finite_all(out, 36) : s == ADAPTIMP_STATUS_BAD_SIZE);
    }
    const double eye2[4] = {1, 0, 0, 1};
    outcome("operational inertia, jacobian NULL", REFUSE,
            adaptimp_operational_inertia(2, NULL, eye2, 1, out), 1);
    outcome("operational inertia, inertia NULL", REFUSE,
            adaptimp_operational_inertia(2, jac9, NULL, 1, out), 1);
    outcome("operational inertia, out NULL", REFUSE,
            adaptimp_operational_inertia(2, jac9, eye2, 1, NULL), 1);
}

typedef struct {
    AdaptimpCartesian *cart;
    AdaptimpCartesianState *state;
} Cart;

static const double Q0[3] = {0.1, 0.05, -0.2};

static AdaptimpStatus open_cart(const AdaptimpCartesianParams *cp, Cart *c) {
    AdaptimpJoint j[4];
    AdaptimpTransform tip;
    arm(j, &tip);
    AdaptimpChain *ch = NULL;
    if (adaptimp_chain_new(j, 4, &tip, &ch) != ADAPTIMP_STATUS_OK) abort();
    AdaptimpParams p;
    if (adaptimp_params_default(&p, 3, ADAPTIMP_LAW_STATE_FEEDBACK, ADAPTIMP_PRESET_ROBOT) !=
        ADAPTIMP_STATUS_OK)
        abort();
    p.impedance = ADAPTIMP_IMPEDANCE_EXTERNAL;
    static double centre[4 * 3 * 4];
    for (int i = 0; i < 4 * 3 * 4; i++) centre[i] = 0.05 * (i % 5) - 0.1;
    p.centers = centre;
    p.nodes = 4;
    c->cart = NULL;
    c->state = NULL;
    AdaptimpStatus s = adaptimp_cartesian_new(ch, cp, &p, &c->cart);
    adaptimp_chain_free(ch);
    if (s != ADAPTIMP_STATUS_OK) return s;
    if (adaptimp_cartesian_state_new(c->cart, 3, Q0, &c->state) != ADAPTIMP_STATUS_OK) abort();
    return s;
}

static void close_cart(Cart *c) {
    adaptimp_cartesian_state_free(c->state);
    adaptimp_cartesian_free(c->cart);
}

/* The start pose as a target at rest. */
static AdaptimpPoseTarget start_target(void) {
    AdaptimpJoint j[4];
    AdaptimpTransform tip;
    arm(j, &tip);
    AdaptimpChain *ch = NULL;
    AdaptimpTip t;
    if (adaptimp_chain_new(j, 4, &tip, &ch) != ADAPTIMP_STATUS_OK ||
        adaptimp_chain_tip(ch, 3, Q0, NULL, &t) != ADAPTIMP_STATUS_OK)
        abort();
    adaptimp_chain_free(ch);
    AdaptimpPoseTarget g;
    memset(&g, 0, sizeof g);
    memcpy(g.p, t.position, sizeof g.p);
    memcpy(g.rotation, t.rotation, sizeof g.rotation);
    return g;
}

static void cartesian(void) {
    char what[160];
    AdaptimpCartesianParams cp;
    if (adaptimp_cartesian_params_default(&cp) != ADAPTIMP_STATUS_OK) abort();
    const AdaptimpPoseTarget good = start_target();
    const double dq[3] = {0.0, 0.0, 0.0}, wrench0[6] = {0};
    /* Every field of a target, every wrench entry, q: every bad value. */
    for (int f = 0; f < 28; f++) {
        for (int b = 0; b < NBAD; b++) {
            Cart c;
            if (open_cart(&cp, &c) != ADAPTIMP_STATUS_OK) abort();
            AdaptimpCartesianCommand o;
            AdaptimpPoseTarget t = good;
            for (int k = 0; k < 3; k++)
                if (adaptimp_cartesian_step(c.cart, c.state, 3, Q0, dq, wrench0, &t, &o) !=
                    ADAPTIMP_STATUS_OK)
                    abort();
            double wrench[6] = {0}, q[3] = {Q0[0], Q0[1], Q0[2]};
            double *field = f < 3    ? &t.p[f]
                            : f < 6  ? &t.dp[f - 3]
                            : f < 9  ? &t.ddp[f - 6]
                            : f < 18 ? &t.rotation[(f - 9) / 3][(f - 9) % 3]
                            : f < 21 ? &t.w[f - 18]
                            : f < 24 ? &t.dw[f - 21]
                            : f < 27 ? &wrench[f - 24]
                                     : &q[1];
            const double was = *field;
            *field = BAD[b];
            const int rot = f >= 9 && f < 18;
            /* The ceilings: a target's 1e6 (m, m/s, m/s², rad/s, rad/s²), the
               wrench's 1e9, q's 1e6 rad; a rotation entry changed is no rotation. */
            const double ceiling = f >= 24 && f < 27 ? 1e9 : 1e6;
            const int bad = !isfinite(BAD[b]) || (rot && BAD[b] != was) ||
                            (!rot && fabs(BAD[b]) > ceiling);
            memset(&o, 0xAB, sizeof o);
            AdaptimpStatus s = adaptimp_cartesian_step(c.cart, c.state, 3, q, dq, wrench, &t, &o);
            double applied[3];
            int ok = o.n == 3 && finite_all(o.tau_sat, 3) &&
                     adaptimp_cartesian_state_applied(c.state, 3, applied) == ADAPTIMP_STATUS_OK;
            if (s == ADAPTIMP_STATUS_OK) {
                ok = ok && adaptimp_cartesian_state_steps(c.state) == 4;
            } else {
                ok = ok && adaptimp_cartesian_state_steps(c.state) == 3 &&
                     adaptimp_cartesian_state_fault(c.state, NULL) &&
                     memcmp(o.tau_sat, applied, sizeof applied) == 0;
            }
            /* Not bricked. */
            AdaptimpPoseTarget g = good;
            ok = ok && adaptimp_cartesian_step(c.cart, c.state, 3, Q0, dq, wrench0, &g, &o) ==
                           ADAPTIMP_STATUS_OK;
            snprintf(what, sizeof what, "Cartesian input %d = %g", f, BAD[b]);
            outcome(what, bad ? REFUSE : EITHER, s, ok);
            close_cart(&c);
        }
    }
    /* Rotations near and far from orthonormal: within 1e-6 accepted, beyond refused. */
    const double eps[] = {1e-9, 1e-7, 5e-7, 2e-6, 1e-5, 1e-3, 0.1};
    for (size_t e = 0; e < sizeof eps / sizeof eps[0]; e++) {
        for (int entry = 0; entry < 9; entry++) {
            Cart c;
            if (open_cart(&cp, &c) != ADAPTIMP_STATUS_OK) abort();
            AdaptimpPoseTarget t = good;
            AdaptimpCartesianCommand o;
            t.rotation[entry / 3][entry % 3] += eps[e];
            AdaptimpStatus s = adaptimp_cartesian_step(c.cart, c.state, 3, Q0, dq, wrench0, &t, &o);
            snprintf(what, sizeof what, "rotation[%d] + %g", entry, eps[e]);
            /* |RᵀR − I| grows as 2 eps |R_ij|: refused beyond 1e-6, near it either. */
            outcome(what, eps[e] <= 1e-7 ? ACCEPT : eps[e] >= 2e-6 ? REFUSE : EITHER, s,
                    o.n == 3 && finite_all(o.tau_sat, 3));
            close_cart(&c);
        }
    }
    /* Quaternions: unit ones accepted, any other refused, the target unchanged. */
    for (int b = 0; b < NBAD; b++) {
        AdaptimpPoseTarget t = good, before = good;
        const double quat[4] = {BAD[b], 0.0, 0.6, 0.8};
        AdaptimpStatus s = adaptimp_pose_target_set_quaternion(&t, quat);
        snprintf(what, sizeof what, "quaternion [%g, 0, 0.6, 0.8]", BAD[b]);
        /* A unit quaternion to 1e-6. */
        outcome(what, fabs(BAD[b]) <= 1e-6 ? ACCEPT : REFUSE, s,
                s == ADAPTIMP_STATUS_OK || memcmp(&t, &before, sizeof t) == 0);
    }
    /* Cartesian parameters: every real field, every bad value; bools. */
    for (int f = 0; f < 26; f++) {
        for (int b = 0; b < NBAD; b++) {
            AdaptimpCartesianParams p = cp;
            double *field = f < 3    ? &p.md[f]
                            : f < 6  ? &p.kd[f - 3]
                            : f < 9  ? &p.md_rot[f - 6]
                            : f < 12 ? &p.kd_rot[f - 9]
                            : f < 15 ? &p.bd[f - 12]
                            : f == 15 ? &p.clik_kp
                            : f == 16 ? &p.clik_kd
                            : f == 17 ? &p.clik_lambda
                            : f == 18 ? &p.clik_lambda_rot
                            : f == 19 ? &p.null_k
                            : f == 20 ? &p.null_d
                            : f == 21 ? &p.pos_error_max
                            : f == 22 ? &p.rot_error_max
                            : f == 23 ? &p.target_filter
                            : f == 24 ? &p.force_filter
                                      : &p.bd_rot[0];
            *field = BAD[b];
            if (f >= 12 && f < 15) p.bd_critical = false;
            if (f == 25) p.bd_rot_critical = false;
            Cart c;
            AdaptimpStatus s = open_cart(&p, &c);
            int ok = (s == ADAPTIMP_STATUS_OK) == (c.cart != NULL);
            if (s == ADAPTIMP_STATUS_OK) {
                AdaptimpPoseTarget t = good;
                AdaptimpCartesianCommand o;
                for (int k = 0; ok && k < 30; k++) {
                    AdaptimpStatus st =
                        adaptimp_cartesian_step(c.cart, c.state, 3, Q0, dq, wrench0, &t, &o);
                    ok = st != ADAPTIMP_STATUS_INTERNAL && o.n == 3 && finite_all(o.tau_sat, 3);
                }
                close_cart(&c);
            }
            snprintf(what, sizeof what, "Cartesian parameter %d = %g", f, BAD[b]);
            outcome(what, isnan(BAD[b]) ? REFUSE : EITHER, s, ok);
        }
    }
    for (unsigned v = 0; v < 4; v++) {
        AdaptimpCartesianParams p = cp;
        unsigned char raw = v == 3 ? 255 : (unsigned char)v;
        memcpy(&p.force_feedforward, &raw, 1);
        Cart c;
        AdaptimpStatus s = open_cart(&p, &c);
        if (s == ADAPTIMP_STATUS_OK) close_cart(&c);
        snprintf(what, sizeof what, "force_feedforward byte = %u", raw);
        outcome(what, raw <= 1 ? ACCEPT : REFUSE, s, 1);
    }
}

/* ---- Issue 33: postures, starts, axes, rates, orbits. ---- */

/* A Cartesian state steps (OK) k times from Q0 toward the start pose. */
static int cart_steps_ok(const Cart *c, int k) {
    const double dq[3] = {0}, w[6] = {0};
    AdaptimpPoseTarget g = start_target();
    AdaptimpCartesianCommand o;
    for (int i = 0; i < k; i++)
        if (adaptimp_cartesian_step(c->cart, c->state, 3, Q0, dq, w, &g, &o) != ADAPTIMP_STATUS_OK ||
            !finite_all(o.tau_sat, 3))
            return 0;
    return 1;
}

static void postures(void) {
    char what[160];
    AdaptimpCartesianParams cp;
    if (adaptimp_cartesian_params_default(&cp) != ADAPTIMP_STATUS_OK) abort();
    /* A posture: refused when given if far out of range (then every step
       used to be refused), accepted otherwise; either way the loop steps. */
    const double far[] = {1e7, -1e7, 2e6, 1e6 + 1, 1e5, 4.1e4, 1e4, 10.0, 0.0};
    for (size_t f = 0; f < sizeof far / sizeof far[0]; f++) {
        for (int j = 0; j < 3; j++) {
            Cart c;
            if (open_cart(&cp, &c) != ADAPTIMP_STATUS_OK) abort();
            double p[3] = {Q0[0], Q0[1], Q0[2]};
            p[j] = far[f];
            const AdaptimpStatus s = adaptimp_cartesian_set_posture(c.cart, c.state, 3, p);
            /* null_k = 25: a pull beyond 1e6 rad/s² is refused. */
            const int bad = 25.0 * fabs(far[f] - Q0[j]) > 1e6;
            snprintf(what, sizeof what, "set_posture[%d] = %g", j, far[f]);
            outcome(what, bad ? REFUSE : ACCEPT, s,
                    (s == ADAPTIMP_STATUS_OK || s == ADAPTIMP_STATUS_INVALID_CONFIG) &&
                        cart_steps_ok(&c, 10));
            close_cart(&c);
        }
    }
    /* A start: within 1e6 rad accepted (the step decides), beyond refused. */
    for (int b = 0; b < NBAD; b++) {
        Cart c;
        if (open_cart(&cp, &c) != ADAPTIMP_STATUS_OK) abort();
        double q0[3] = {Q0[0], BAD[b], Q0[2]};
        AdaptimpCartesianState *st = NULL;
        AdaptimpStatus s = adaptimp_cartesian_state_new(c.cart, 3, q0, &st);
        snprintf(what, sizeof what, "cartesian_state_new q0[1] = %g", BAD[b]);
        const int bad = !isfinite(BAD[b]) || fabs(BAD[b]) > 1e6;
        outcome(what, bad ? REFUSE : ACCEPT, s, (s == ADAPTIMP_STATUS_OK) == (st != NULL));
        adaptimp_cartesian_state_free(st);
        s = adaptimp_cartesian_state_reset(c.cart, c.state, 3, q0);
        snprintf(what, sizeof what, "cartesian_state_reset q0[1] = %g", BAD[b]);
        outcome(what, bad ? REFUSE : ACCEPT, s, 1);
        /* A refused reset changed nothing: the state still steps. */
        if (s != ADAPTIMP_STATUS_OK) {
            snprintf(what, sizeof what, "steps after a refused reset to %g", BAD[b]);
            outcome(what, ACCEPT, ADAPTIMP_STATUS_OK, cart_steps_ok(&c, 5));
        }
        close_cart(&c);
    }
    /* Axes of every magnitude: an axis whose norm overflows is an axis. */
    const double scales[] = {1e-11, 1e-3, 1.0, 1e100, 1e200, 1e300, DBL_MAX, 1e-13, 0.0};
    AdaptimpTip ref;
    {
        AdaptimpJoint j[4];
        AdaptimpTransform tip;
        arm(j, &tip);
        AdaptimpChain *ch = NULL;
        if (adaptimp_chain_new(j, 4, &tip, &ch) != ADAPTIMP_STATUS_OK ||
            adaptimp_chain_tip(ch, 3, Q0, Q0, &ref) != ADAPTIMP_STATUS_OK)
            abort();
        adaptimp_chain_free(ch);
    }
    for (size_t k = 0; k < sizeof scales / sizeof scales[0]; k++) {
        AdaptimpJoint j[4];
        AdaptimpTransform tip;
        arm(j, &tip);
        for (int i = 0; i < 3; i++) j[0].axis[i] *= scales[k];
        AdaptimpChain *ch = NULL;
        const AdaptimpStatus s = adaptimp_chain_new(j, 4, &tip, &ch);
        AdaptimpTip t;
        int ok = (s == ADAPTIMP_STATUS_OK) == (ch != NULL);
        if (ch) {
            /* The same chain as the unit axis's, to rounding. */
            ok = ok && adaptimp_chain_tip(ch, 3, Q0, Q0, &t) == ADAPTIMP_STATUS_OK;
            for (int r = 0; ok && r < 6; r++)
                for (int i = 0; i < 3; i++)
                    ok = ok && fabs(t.jacobian[r][i] - ref.jacobian[r][i]) < 1e-12;
            adaptimp_chain_free(ch);
        }
        snprintf(what, sizeof what, "joint axis × %g", scales[k]);
        outcome(what, scales[k] >= 1e-11 ? ACCEPT : REFUSE, s, ok);
    }
    /* Rates: the tip's J̇ q̇ finite or refused, never NaN with OK. */
    for (int b = 0; b < NBAD; b++) {
        AdaptimpJoint j[4];
        AdaptimpTransform tip;
        arm(j, &tip);
        AdaptimpChain *ch = NULL;
        if (adaptimp_chain_new(j, 4, &tip, &ch) != ADAPTIMP_STATUS_OK) abort();
        double dq[3] = {BAD[b], 0.1, 0.0};
        AdaptimpTip t;
        const AdaptimpStatus s = adaptimp_chain_tip(ch, 3, Q0, dq, &t);
        snprintf(what, sizeof what, "chain_tip dq[0] = %g", BAD[b]);
        const int bad = !isfinite(BAD[b]) || fabs(BAD[b]) > 1e6;
        outcome(what, bad ? REFUSE : ACCEPT, s,
                s != ADAPTIMP_STATUS_OK || (finite_all(t.bias, 6) && finite_all(t.position, 3)));
        double q[3] = {Q0[0], BAD[b], Q0[2]};
        const AdaptimpStatus s2 = adaptimp_chain_tip(ch, 3, q, NULL, &t);
        snprintf(what, sizeof what, "chain_tip q[1] = %g", BAD[b]);
        outcome(what, bad ? REFUSE : ACCEPT, s2,
                s2 != ADAPTIMP_STATUS_OK || (finite_all(t.bias, 6) && finite_all(t.position, 3)));
        adaptimp_chain_free(ch);
    }
    /* Orbits: a huge `nodes` allocates no more than one sample a step; a
       zero one is refused; the number of steps is bounded. */
    {
        AdaptimpJoint j[4];
        AdaptimpTransform tip;
        arm(j, &tip);
        AdaptimpChain *ch = NULL;
        if (adaptimp_chain_new(j, 4, &tip, &ch) != ADAPTIMP_STATUS_OK) abort();
        AdaptimpPoseTarget path[8];
        for (int k = 0; k < 8; k++) path[k] = start_target();
        const double tube[2] = {0.05, 0.2};
        static double centres[8 * 12];
        double w2[12];
        const size_t nodes[] = {1, 8, 9, (size_t)1 << 40, SIZE_MAX / 96, 0};
        for (size_t k = 0; k < sizeof nodes / sizeof nodes[0]; k++) {
            size_t written = 99;
            /* The contract is room for `nodes` rows: the huge ones get NULL
               (refused before anything is allocated or written). */
            double *out = nodes[k] <= 9 ? centres : NULL;
            const AdaptimpStatus s = adaptimp_cartesian_orbit_centres(
                ch, &cp, 1e-3, 3, Q0, path, 8, nodes[k], tube, out, w2, &written);
            snprintf(what, sizeof what, "orbit_centres nodes = %zu", nodes[k]);
            const int good = nodes[k] >= 1 && nodes[k] <= 9;
            outcome(what, good ? ACCEPT : REFUSE, s,
                    s != ADAPTIMP_STATUS_OK || written == (nodes[k] < 8 ? nodes[k] : 8));
        }
        adaptimp_chain_free(ch);
    }
}

/* ---- Robot descriptions: adaptimp_chain_from_urdf. ---- */

/* A 4-joint arm (3 revolute, one prismatic rail on a finger, which the rule
   holds) with one field replaced by `value` when `field` >= 0. */
static const char *URDF_FIELDS[] = {
    "origin xyz", "origin rpy", "axis xyz", "mass", "inertia ixx", "limit lower",
    "limit upper", "limit effort", "limit velocity", "dynamics damping",
    "dynamics friction", "mimic multiplier"};
enum { NURDF_FIELDS = sizeof URDF_FIELDS / sizeof URDF_FIELDS[0] };
static const char *URDF_VALUES[] = {"nan",  "inf",  "-inf", "1e400",  "1e200", "-1", "0",
                                    "1e-320", "abc", "",     "1 2",    "0 0 0", "1e9 0 0",
                                    "0 0 1e200", "-0", "1e308 1e308 1e308"};
enum { NURDF_VALUES = sizeof URDF_VALUES / sizeof URDF_VALUES[0] };

static char *urdf_text(int field, const char *value) {
    const char *v[NURDF_FIELDS];
    static const char *normal[NURDF_FIELDS] = {"0 0 0.1", "0 0 0", "0 1 0", "0.5", "0.01",
                                               "-2",      "2",     "10",    "3",   "0.1",
                                               "0.05",    "1"};
    for (int i = 0; i < NURDF_FIELDS; i++) v[i] = i == field ? value : normal[i];
    size_t cap = 16384;
    char *t = malloc(cap);
    if (!t) abort();
    int len = snprintf(t, cap, "<robot name='probe'><link name='base'/>");
    const char *links[5] = {"base", "l1", "l2", "l3", "jaw"};
    for (int j = 0; j < 4; j++) {
        len += snprintf(
            t + len, cap - (size_t)len,
            "<link name='%s'><inertial><origin xyz='0 0 0.05'/><mass value='%s'/>"
            "<inertia ixx='%s' ixy='0' ixz='0' iyy='0.01' iyz='0' izz='0.01'/></inertial></link>"
            "<joint name='j%d' type='%s'><parent link='%s'/><child link='%s'/>"
            "<origin xyz='%s' rpy='%s'/><axis xyz='%s'/>"
            "<limit lower='%s' upper='%s' effort='%s' velocity='%s'/>"
            "<dynamics damping='%s' friction='%s'/>%s%s%s</joint>",
            links[j + 1], v[3], v[4], j + 1, j == 3 ? "prismatic" : "revolute", links[j],
            links[j + 1], v[0], v[1], v[2], v[5], v[6], v[7], v[8], v[9], v[10],
            j == 3 ? "<mimic joint='j3' multiplier='" : "", j == 3 ? v[11] : "",
            j == 3 ? "'/>" : "");
    }
    snprintf(t + len, cap - (size_t)len, "</robot>");
    return t;
}

/* One call: its status, and the invariants: *out written exactly when OK
   (preset to a sentinel), the chain's tip finite with every movable joint's
   Jacobian column non-zero, the info's n the chain's, its drive terms finite
   and not negative. */
static int from_urdf(const char *source, const char *tip, const char *const *fix, size_t nfix,
                     AdaptimpStatus *status) {
    AdaptimpChain *sentinel = (AdaptimpChain *)(uintptr_t)0x10;
    AdaptimpChain *ch = sentinel;
    AdaptimpArmInfo info;
    memset(&info, 0xff, sizeof info);
    const AdaptimpStatus s = adaptimp_chain_from_urdf(source, tip, fix, nfix, &ch, &info);
    *status = s;
    if (s != ADAPTIMP_STATUS_OK) return ch == sentinel;
    if (ch == sentinel || ch == NULL) return 0;
    const size_t n = adaptimp_chain_joints(ch);
    int ok = n >= 1 && n <= ADAPTIMP_MAX_JOINTS && info.n == n;
    double q[ADAPTIMP_MAX_JOINTS], dq[ADAPTIMP_MAX_JOINTS];
    for (size_t i = 0; i < n; i++) {
        q[i] = 0.1 * (double)(i + 1);
        dq[i] = -0.2;
    }
    AdaptimpTip t;
    ok = ok && adaptimp_chain_tip(ch, n, q, dq, &t) == ADAPTIMP_STATUS_OK &&
         finite_all(t.position, 3) && finite_all(&t.rotation[0][0], 9) && finite_all(t.bias, 6);
    for (size_t i = 0; ok && i < n; i++) {
        double norm = 0.0;
        for (int r = 0; r < 6; r++) norm += t.jacobian[r][i] * t.jacobian[r][i];
        ok = norm > 0.0 && isfinite(norm) && !isnan(info.lower[i]) && !isnan(info.upper[i]) &&
             !(info.lower[i] > info.upper[i]) &&
             isfinite(info.damping[i]) && info.damping[i] >= 0.0 &&
             isfinite(info.friction[i]) && info.friction[i] >= 0.0 &&
             !(info.effort[i] <= 0.0) && !(info.velocity[i] <= 0.0);
    }
    /* Freed, its handle is dead: refused, never read. */
    adaptimp_chain_free(ch);
    ok = ok && adaptimp_chain_joints(ch) == 0 &&
         adaptimp_chain_tip(ch, n, q, dq, &t) == ADAPTIMP_STATUS_BAD_HANDLE;
    adaptimp_chain_free(ch); /* twice: ignored */
    return ok;
}

static void descriptions(void) {
    char what[200];
    AdaptimpStatus s;
    /* Sources no arm is read from. */
    char *deep = malloc(7 * 100000 + 64);
    if (!deep) abort();
    size_t len = (size_t)sprintf(deep, "<robot name='r'>");
    for (int i = 0; i < 100000; i++) len += (size_t)sprintf(deep + len, "<a>");
    for (int i = 0; i < 100000; i++) len += (size_t)sprintf(deep + len, "</a>");
    sprintf(deep + len, "</robot>");
    char xacro_text[] =
        "<robot name='x' xmlns:xacro='http://www.ros.org/wiki/xacro'>"
        "<xacro:property name='l' value='1'/><link name='a'/></robot>";
    char nine[8192];
    int n9 = snprintf(nine, sizeof nine, "<robot name='nine'><link name='l0'/>");
    for (int i = 1; i <= 9; i++)
        n9 += snprintf(nine + n9, sizeof nine - (size_t)n9,
                       "<link name='l%d'/><joint name='j%d' type='continuous'><parent link='l%d'/>"
                       "<child link='l%d'/><origin xyz='0 0 0.1'/><axis xyz='0 1 0'/></joint>",
                       i, i, i - 1, i);
    snprintf(nine + n9, sizeof nine - (size_t)n9, "</robot>");
    struct {
        const char *name, *source;
    } bad[] = {
        {"NULL", NULL},
        {"an empty string", ""},
        {"bytes that are not UTF-8", "\xff\xfe<robot/>"},
        {"a directory", "/"},
        {"a device that never ends", "/dev/zero"},
        {"a file that is not there", "/nonexistent/arm.urdf"},
        {"'<'", "<"},
        {"an unclosed root", "<robot name='x'><link name='a'>"},
        {"improper nesting", "<robot><a></robot></a>"},
        {"an empty robot", "<robot name='x'/>"},
        {"a link and no joint", "<robot name='x'><link name='a'/></robot>"},
        {"MJCF text", "<mujoco><worldbody/></mujoco>"},
        {"xacro text", xacro_text},
        {"100 000 nested elements", deep},
        {"a loop", "<robot name='x'><link name='a'/><link name='b'/>"
                   "<joint name='j' type='revolute'><parent link='a'/><child link='b'/>"
                   "<limit lower='-1' upper='1' effort='1' velocity='1'/></joint>"
                   "<joint name='k' type='revolute'><parent link='b'/><child link='a'/>"
                   "<limit lower='-1' upper='1' effort='1' velocity='1'/></joint></robot>"},
        {"a joint to a missing link", "<robot name='x'><link name='a'/>"
                   "<joint name='j' type='continuous'><parent link='a'/><child link='b'/></joint>"
                   "</robot>"},
        {"nine joints", nine},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        const int ok = from_urdf(bad[i].source, NULL, NULL, 0, &s);
        snprintf(what, sizeof what, "source: %s", bad[i].name);
        outcome(what, REFUSE, s, ok);
        if (i == 0 && s != ADAPTIMP_STATUS_NULL_POINTER) note("%s: not NULL_POINTER%s", what, "");
        if (bad[i].source == nine && s != ADAPTIMP_STATUS_BAD_SIZE)
            note("%s: not BAD_SIZE%s", what, "");
    }
    free(deep);
    /* Every field of every joint's element replaced by a bad value. */
    for (int f = 0; f < NURDF_FIELDS; f++) {
        for (int v = 0; v < NURDF_VALUES; v++) {
            char *text = urdf_text(f, URDF_VALUES[v]);
            const int ok = from_urdf(text, NULL, NULL, 0, &s);
            snprintf(what, sizeof what, "%s = '%s'", URDF_FIELDS[f], URDF_VALUES[v]);
            outcome(what, EITHER, s, ok);
            free(text);
        }
    }
    /* A good arm: tips and fixes, good and bad strings. */
    char *good = urdf_text(-1, "");
    const int ok = from_urdf(good, NULL, NULL, 0, &s);
    outcome("the probe's arm", ACCEPT, s, ok);
    struct {
        const char *name, *tip;
        int expect;
    } tips[] = {
        {"tip NULL", NULL, ACCEPT},     {"tip l2", "l2", ACCEPT},
        {"tip base", "base", REFUSE},   {"tip ''", "", REFUSE},
        {"tip not UTF-8", "\xc3\x28", REFUSE}, {"tip missing", "no_such_link", REFUSE},
        {"tip the jaw (beyond the rail)", "jaw", EITHER},
        {"tip a joint's name", "j1", REFUSE},
    };
    for (size_t i = 0; i < sizeof tips / sizeof tips[0]; i++) {
        const int good_ok = from_urdf(good, tips[i].tip, NULL, 0, &s);
        outcome(tips[i].name, tips[i].expect, s, good_ok);
    }
    const char *fix_j2[] = {"j2"}, *fix_null[] = {"j1", NULL}, *fix_bad[] = {"\xff"},
               *fix_none[] = {"nope"}, *fix_twice[] = {"j2", "j2"},
               *fix_all[] = {"j1", "j2", "j3", "j4"};
    struct {
        const char *name;
        const char *const *fix;
        size_t n;
        int expect;
    } fixes[] = {
        {"fix j2", fix_j2, 1, ACCEPT},
        {"fix NULL with nfix 2", NULL, 2, REFUSE},
        {"fix holding NULL", fix_null, 2, REFUSE},
        {"fix not UTF-8", fix_bad, 1, REFUSE},
        {"fix an unknown joint", fix_none, 1, REFUSE},
        {"fix a joint twice", fix_twice, 2, EITHER},
        {"fix every joint", fix_all, 4, REFUSE},
        {"fix NULL with nfix 0", NULL, 0, ACCEPT},
    };
    for (size_t i = 0; i < sizeof fixes / sizeof fixes[0]; i++) {
        const int fix_ok = from_urdf(good, NULL, fixes[i].fix, fixes[i].n, &s);
        outcome(fixes[i].name, fixes[i].expect, s, fix_ok);
    }
    /* out NULL: refused, nothing leaked; info NULL: accepted. */
    s = adaptimp_chain_from_urdf(good, NULL, NULL, 0, NULL, NULL);
    outcome("out NULL", REFUSE, s, 1);
    AdaptimpChain *ch = NULL;
    s = adaptimp_chain_from_urdf(good, NULL, NULL, 0, &ch, NULL);
    outcome("info NULL", ACCEPT, s, ch != NULL);
    /* The chain it made is a chain and nothing else: as any other kind it is
       refused; a Cartesian controller can be built on it. */
    const size_t n = adaptimp_chain_joints(ch);
    const int mistyped =
        n == 2 && /* j3 drives the mimic j4: both held, the gripper's */
        !adaptimp_state_fault((AdaptimpState *)ch, NULL) &&
        !adaptimp_cartesian_state_fault((AdaptimpCartesianState *)ch, NULL) &&
        adaptimp_state_steps((AdaptimpState *)ch) == 0 &&
        adaptimp_cartesian_state_steps((AdaptimpCartesianState *)ch) == 0 &&
        adaptimp_controller_joints((AdaptimpController *)ch) == 0 &&
        adaptimp_cartesian_joints((AdaptimpCartesian *)ch) == 0;
    outcome("its chain as every other kind", EITHER, ADAPTIMP_STATUS_OK, mistyped);
    AdaptimpCartesianParams cp;
    AdaptimpParams p;
    if (adaptimp_cartesian_params_default(&cp) != ADAPTIMP_STATUS_OK ||
        adaptimp_params_default(&p, 2, ADAPTIMP_LAW_STATE_FEEDBACK, ADAPTIMP_PRESET_ROBOT) !=
            ADAPTIMP_STATUS_OK)
        abort();
    p.impedance = ADAPTIMP_IMPEDANCE_EXTERNAL;
    static double centre[4 * 2 * 4];
    for (int i = 0; i < 4 * 2 * 4; i++) centre[i] = 0.05 * (i % 5) - 0.1;
    p.centers = centre;
    p.nodes = 4;
    AdaptimpCartesian *cart = NULL;
    s = adaptimp_cartesian_new(ch, &cp, &p, &cart);
    outcome("a Cartesian controller on it", ACCEPT, s, cart != NULL);
    adaptimp_cartesian_free(cart);
    adaptimp_chain_free(ch);
    free(good);
}

/* ---- Forged handles at every entry point. ---- */

/* The live handles of one world; every entry point is called with one of its
   handle arguments replaced by a bad one, the others live. */
typedef struct {
    AdaptimpController *ctrl;
    AdaptimpState *state;
    AdaptimpChain *chain;
    AdaptimpCartesian *cart;
    AdaptimpCartesianState *cstate;
} World;

enum { KIND_CTRL, KIND_STATE, KIND_CHAIN, KIND_CART, KIND_CSTATE, NKINDS };
static const char *KIND_NAMES[NKINDS] = {"controller", "state", "chain", "Cartesian",
                                         "Cartesian state"};

static void open_world(World *w) {
    AdaptimpParams p = robot(ADAPTIMP_LAW_STATE_FEEDBACK);
    if (adaptimp_controller_new(&p, &w->ctrl) != ADAPTIMP_STATUS_OK ||
        adaptimp_state_new(w->ctrl, &w->state) != ADAPTIMP_STATUS_OK)
        abort();
    AdaptimpJoint j[4];
    AdaptimpTransform tip;
    arm(j, &tip);
    if (adaptimp_chain_new(j, 4, &tip, &w->chain) != ADAPTIMP_STATUS_OK) abort();
    AdaptimpCartesianParams cp;
    if (adaptimp_cartesian_params_default(&cp) != ADAPTIMP_STATUS_OK) abort();
    Cart c;
    if (open_cart(&cp, &c) != ADAPTIMP_STATUS_OK) abort();
    w->cart = c.cart;
    w->cstate = c.state;
}

static void close_world(World *w) {
    adaptimp_cartesian_state_free(w->cstate);
    adaptimp_cartesian_free(w->cart);
    adaptimp_chain_free(w->chain);
    adaptimp_state_free(w->state);
    adaptimp_controller_free(w->ctrl);
}

/* The live handle of `kind` in `w`. */
static void *live_of(const World *w, int kind) {
    switch (kind) {
    case KIND_CTRL: return w->ctrl;
    case KIND_STATE: return w->state;
    case KIND_CHAIN: return w->chain;
    case KIND_CART: return w->cart;
    default: return w->cstate;
    }
}

/* Each entry point and the kinds of its handle arguments (-1: none). */
typedef struct {
    const char *name;
    int kinds[2];
} Entry;

static const Entry ENTRIES[] = {
    {"adaptimp_controller_joints", {KIND_CTRL, -1}},
    {"adaptimp_controller_period", {KIND_CTRL, -1}},
    {"adaptimp_state_new", {KIND_CTRL, -1}},
    {"adaptimp_state_buffer_size", {KIND_CTRL, -1}},
    {"adaptimp_state_init", {KIND_CTRL, -1}},
    {"adaptimp_state_reset", {KIND_STATE, -1}},
    {"adaptimp_state_fault", {KIND_STATE, -1}},
    {"adaptimp_state_clear_fault", {KIND_STATE, -1}},
    {"adaptimp_state_steps", {KIND_STATE, -1}},
    {"adaptimp_state_applied", {KIND_STATE, -1}},
    {"adaptimp_state_snapshot_len", {KIND_STATE, -1}},
    {"adaptimp_state_save", {KIND_STATE, -1}},
    {"adaptimp_state_restore", {KIND_CTRL, KIND_STATE}},
    {"adaptimp_state_take_over", {KIND_CTRL, KIND_STATE}},
    {"adaptimp_step", {KIND_CTRL, KIND_STATE}},
    {"adaptimp_chain_joints", {KIND_CHAIN, -1}},
    {"adaptimp_chain_tip", {KIND_CHAIN, -1}},
    {"adaptimp_cartesian_new", {KIND_CHAIN, -1}},
    {"adaptimp_cartesian_orbit_centres", {KIND_CHAIN, -1}},
    {"adaptimp_cartesian_joints", {KIND_CART, -1}},
    {"adaptimp_cartesian_period", {KIND_CART, -1}},
    {"adaptimp_cartesian_state_new", {KIND_CART, -1}},
    {"adaptimp_cartesian_state_buffer_size", {KIND_CART, -1}},
    {"adaptimp_cartesian_state_init", {KIND_CART, -1}},
    {"adaptimp_cartesian_state_reset", {KIND_CART, KIND_CSTATE}},
    {"adaptimp_cartesian_set_stiffness", {KIND_CART, KIND_CSTATE}},
    {"adaptimp_cartesian_step", {KIND_CART, KIND_CSTATE}},
    {"adaptimp_cartesian_set_posture", {KIND_CART, KIND_CSTATE}},
    {"adaptimp_cartesian_state_fault", {KIND_CSTATE, -1}},
    {"adaptimp_cartesian_state_clear_fault", {KIND_CSTATE, -1}},
    {"adaptimp_cartesian_state_steps", {KIND_CSTATE, -1}},
    {"adaptimp_cartesian_state_applied", {KIND_CSTATE, -1}},
    /* The frees last: a bad handle is ignored, the live ones stay live. */
    {"adaptimp_controller_free", {KIND_CTRL, -1}},
    {"adaptimp_state_free", {KIND_STATE, -1}},
    {"adaptimp_chain_free", {KIND_CHAIN, -1}},
    {"adaptimp_cartesian_free", {KIND_CART, -1}},
    {"adaptimp_cartesian_state_free", {KIND_CSTATE, -1}},
};
enum { NENTRIES = sizeof ENTRIES / sizeof ENTRIES[0] };

/* Call entry `e` with the handle of `kind` h[kind] (the others as given):
   1 if it refused as it must (BAD_HANDLE or NULL_POINTER, a getter's "none"
   value, outputs untouched or zeroed as documented), 0 otherwise; *status the
   status (OK for the void and value-returning ones that refused). */
static int call_entry(int e, void *h[NKINDS], AdaptimpStatus *status) {
    AdaptimpController *ctrl = h[KIND_CTRL];
    AdaptimpState *state = h[KIND_STATE];
    AdaptimpChain *chain = h[KIND_CHAIN];
    AdaptimpCartesian *cart = h[KIND_CART];
    AdaptimpCartesianState *cstate = h[KIND_CSTATE];
    static const double q3[3] = {0.1, 0.05, -0.2}, zero6[6] = {0}, kd[3] = {100, 100, 100};
    double q2[2], dq2[2], te2[2];
    inputs(0, q2, dq2, te2);
    double buf[16] = {0};
    static uint64_t mem[1 << 14];
    size_t size = 7, align = 7, written = 7;
    uint64_t step = 77;
    const char *name = ENTRIES[e].name;
    AdaptimpStatus s = ADAPTIMP_STATUS_OK;
    int ok = 1;
    /* A refusal of a handle: BAD_HANDLE, or NULL_POINTER for NULL. */
#define REFUSED(st) ((st) == ADAPTIMP_STATUS_BAD_HANDLE || (st) == ADAPTIMP_STATUS_NULL_POINTER)
    if (!strcmp(name, "adaptimp_controller_joints")) {
        ok = adaptimp_controller_joints(ctrl) == 0;
    } else if (!strcmp(name, "adaptimp_controller_period")) {
        ok = isnan(adaptimp_controller_period(ctrl));
    } else if (!strcmp(name, "adaptimp_state_new")) {
        AdaptimpState *o = NULL;
        s = adaptimp_state_new(ctrl, &o);
        ok = REFUSED(s) && o == NULL;
    } else if (!strcmp(name, "adaptimp_state_buffer_size")) {
        s = adaptimp_state_buffer_size(ctrl, &size, &align);
        ok = REFUSED(s) && size == 7 && align == 7;
    } else if (!strcmp(name, "adaptimp_state_init")) {
        AdaptimpState *o = NULL;
        s = adaptimp_state_init(ctrl, mem, sizeof mem, &o);
        ok = REFUSED(s) && o == NULL;
    } else if (!strcmp(name, "adaptimp_state_reset")) {
        s = adaptimp_state_reset(state);
        ok = REFUSED(s);
    } else if (!strcmp(name, "adaptimp_state_fault")) {
        ok = !adaptimp_state_fault(state, &step) && step == 77;
    } else if (!strcmp(name, "adaptimp_state_clear_fault")) {
        s = adaptimp_state_clear_fault(state);
        ok = REFUSED(s);
    } else if (!strcmp(name, "adaptimp_state_steps")) {
        ok = adaptimp_state_steps(state) == 0;
    } else if (!strcmp(name, "adaptimp_state_applied")) {
        double tau[2] = {7, 7};
        s = adaptimp_state_applied(state, 2, tau);
        ok = REFUSED(s) && tau[0] == 7 && tau[1] == 7;
    } else if (!strcmp(name, "adaptimp_state_snapshot_len")) {
        ok = adaptimp_state_snapshot_len(state) == 0;
    } else if (!strcmp(name, "adaptimp_state_save")) {
        s = adaptimp_state_save(state, buf, 16, &written);
        ok = REFUSED(s) && written == 7 && buf[0] == 0;
    } else if (!strcmp(name, "adaptimp_state_restore")) {
        s = adaptimp_state_restore(ctrl, state, buf, 16);
        ok = REFUSED(s);
    } else if (!strcmp(name, "adaptimp_state_take_over")) {
        double tau[2] = {0, 0};
        s = adaptimp_state_take_over(ctrl, state, tau, 2);
        ok = REFUSED(s);
    } else if (!strcmp(name, "adaptimp_step")) {
        AdaptimpCommand c;
        memset(&c, 0xAB, sizeof c);
        s = adaptimp_step(ctrl, state, 2, q2, dq2, te2, NULL, &c);
        ok = REFUSED(s) && c.n == 0 && c.tau_sat[0] == 0.0;
    } else if (!strcmp(name, "adaptimp_chain_joints")) {
        ok = adaptimp_chain_joints(chain) == 0;
    } else if (!strcmp(name, "adaptimp_chain_tip")) {
        AdaptimpTip t;
        memset(&t, 0xAB, sizeof t);
        s = adaptimp_chain_tip(chain, 3, q3, NULL, &t);
        ok = REFUSED(s);
    } else if (!strcmp(name, "adaptimp_cartesian_new")) {
        AdaptimpCartesianParams cp;
        if (adaptimp_cartesian_params_default(&cp) != ADAPTIMP_STATUS_OK) abort();
        AdaptimpParams p;
        if (adaptimp_params_default(&p, 3, ADAPTIMP_LAW_PD, ADAPTIMP_PRESET_ROBOT) !=
            ADAPTIMP_STATUS_OK)
            abort();
        p.impedance = ADAPTIMP_IMPEDANCE_EXTERNAL;
        AdaptimpCartesian *o = NULL;
        s = adaptimp_cartesian_new(chain, &cp, &p, &o);
        ok = REFUSED(s) && o == NULL;
    } else if (!strcmp(name, "adaptimp_cartesian_orbit_centres")) {
        AdaptimpCartesianParams cp;
        if (adaptimp_cartesian_params_default(&cp) != ADAPTIMP_STATUS_OK) abort();
        AdaptimpPoseTarget t = start_target();
        const double tube[2] = {0.05, 0.2};
        double centres[4 * 12], w2[12];
        s = adaptimp_cartesian_orbit_centres(chain, &cp, 1e-3, 3, q3, &t, 1, 4, tube, centres, w2,
                                             &written);
        ok = REFUSED(s) && written == 7;
    } else if (!strcmp(name, "adaptimp_cartesian_joints")) {
        ok = adaptimp_cartesian_joints(cart) == 0;
    } else if (!strcmp(name, "adaptimp_cartesian_period")) {
        ok = isnan(adaptimp_cartesian_period(cart));
    } else if (!strcmp(name, "adaptimp_cartesian_state_new")) {
        AdaptimpCartesianState *o = NULL;
        s = adaptimp_cartesian_state_new(cart, 3, q3, &o);
        ok = REFUSED(s) && o == NULL;
    } else if (!strcmp(name, "adaptimp_cartesian_state_buffer_size")) {
        s = adaptimp_cartesian_state_buffer_size(cart, &size, &align);
        ok = REFUSED(s) && size == 7 && align == 7;
    } else if (!strcmp(name, "adaptimp_cartesian_state_init")) {
        AdaptimpCartesianState *o = NULL;
        s = adaptimp_cartesian_state_init(cart, 3, q3, mem, sizeof mem, &o);
        ok = REFUSED(s) && o == NULL;
    } else if (!strcmp(name, "adaptimp_cartesian_state_reset")) {
        s = adaptimp_cartesian_state_reset(cart, cstate, 3, NULL);
        ok = REFUSED(s);
    } else if (!strcmp(name, "adaptimp_cartesian_set_stiffness")) {
        s = adaptimp_cartesian_set_stiffness(cart, cstate, kd, kd);
        ok = REFUSED(s);
    } else if (!strcmp(name, "adaptimp_cartesian_step")) {
        AdaptimpCartesianCommand c;
        memset(&c, 0xAB, sizeof c);
        s = adaptimp_cartesian_step(cart, cstate, 3, q3, q3, zero6, NULL, &c);
        ok = REFUSED(s) && c.n == 0 && c.tau_sat[0] == 0.0;
    } else if (!strcmp(name, "adaptimp_cartesian_set_posture")) {
        s = adaptimp_cartesian_set_posture(cart, cstate, 3, q3);
        ok = REFUSED(s);
    } else if (!strcmp(name, "adaptimp_cartesian_state_fault")) {
        ok = !adaptimp_cartesian_state_fault(cstate, &step) && step == 77;
    } else if (!strcmp(name, "adaptimp_cartesian_state_clear_fault")) {
        s = adaptimp_cartesian_state_clear_fault(cstate);
        ok = REFUSED(s);
    } else if (!strcmp(name, "adaptimp_cartesian_state_steps")) {
        ok = adaptimp_cartesian_state_steps(cstate) == 0;
    } else if (!strcmp(name, "adaptimp_cartesian_state_applied")) {
        double tau[3] = {7, 7, 7};
        s = adaptimp_cartesian_state_applied(cstate, 3, tau);
        ok = REFUSED(s) && tau[0] == 7;
    } else if (!strcmp(name, "adaptimp_controller_free")) {
        adaptimp_controller_free(ctrl);
    } else if (!strcmp(name, "adaptimp_state_free")) {
        adaptimp_state_free(state);
    } else if (!strcmp(name, "adaptimp_chain_free")) {
        adaptimp_chain_free(chain);
    } else if (!strcmp(name, "adaptimp_cartesian_free")) {
        adaptimp_cartesian_free(cart);
    } else if (!strcmp(name, "adaptimp_cartesian_state_free")) {
        adaptimp_cartesian_state_free(cstate);
    } else {
        abort();
    }
#undef REFUSED
    /* A status-returning call names the bad argument in its message. */
    if (s != ADAPTIMP_STATUS_OK) {
        const char *msg = adaptimp_last_error();
        ok = ok && (strstr(msg, "not a live") || strstr(msg, "is a live") || strstr(msg, "is NULL"));
    }
    *status = s;
    return ok;
}

/* The world still works: each live handle answers, and the two states were
   not stepped by anything but this check. */
static int world_intact(const World *w, uint64_t steps, uint64_t csteps) {
    return adaptimp_controller_joints(w->ctrl) == 2 && adaptimp_state_steps(w->state) == steps &&
           adaptimp_chain_joints(w->chain) == 3 && adaptimp_cartesian_joints(w->cart) == 3 &&
           adaptimp_cartesian_state_steps(w->cstate) == csteps;
}

static void forged(void) {
    World w;
    open_world(&w);
    /* Freed handles of each kind: made, freed (the next handles may reuse
       their memory: a stale one must not reach the new object). */
    World dead;
    open_world(&dead);
    close_world(&dead);
    World after; /* made after the frees: the memory of the dead ones */
    open_world(&after);
    /* Memory a foreign pointer may point to: 8 readable bytes before an
       unmapped page, zeroed memory, memory that looks like a handle's tag,
       small integers and unmapped addresses, a live handle's number + 1. */
    const long page = sysconf(_SC_PAGESIZE);
    const int zero_fd = open("/dev/zero", O_RDWR); /* POSIX: no MAP_ANONYMOUS in 2008 */
    unsigned char *pages =
        mmap(NULL, 2 * (size_t)page, PROT_READ | PROT_WRITE, MAP_PRIVATE, zero_fd, 0);
    if (pages == MAP_FAILED || munmap(pages + page, (size_t)page) != 0) abort();
    close(zero_fd);
    memset(pages, 0, (size_t)page);
    static uint64_t zeros[512];
    static uint64_t looks[4];
    memcpy(&looks[0], "adpSTATE", 8);
    enum { NFORGED = 8 };
    void *foreign[NFORGED] = {pages + page - 8, pages + page - 64, zeros, looks,
                              (void *)(uintptr_t)0x1000, (void *)(uintptr_t)1,
                              (void *)(uintptr_t)(UINTPTR_MAX - 7), NULL};
    static const char *foreign_names[NFORGED] = {
        "8 bytes before an unmapped page", "64 bytes before an unmapped page", "zeroed memory",
        "memory that looks like a state",  "address 0x1000", "address 1", "the top address",
        "a live handle's number + 1"};
    char what[200];
    for (int e = 0; e < NENTRIES; e++) {
        for (int a = 0; a < 2; a++) {
            const int kind = ENTRIES[e].kinds[a];
            if (kind < 0) continue;
            /* The bad values for this argument: NULL, the freed handle of its
               kind, a live handle of each other kind, each foreign pointer. */
            void *bad[2 + NKINDS + NFORGED];
            const char *bad_names[2 + NKINDS + NFORGED];
            char other_names[NKINDS][64];
            int nbad = 0;
            bad[nbad] = NULL;
            bad_names[nbad++] = "NULL";
            bad[nbad] = live_of(&dead, kind);
            bad_names[nbad++] = "freed (its memory reused)";
            for (int k = 0; k < NKINDS; k++) {
                if (k == kind) continue;
                snprintf(other_names[k], sizeof other_names[k], "a live %s", KIND_NAMES[k]);
                bad[nbad] = live_of(&w, k);
                bad_names[nbad++] = other_names[k];
            }
            foreign[NFORGED - 1] = (void *)((uintptr_t)live_of(&w, kind) + 1);
            for (int f = 0; f < NFORGED; f++) {
                bad[nbad] = foreign[f];
                bad_names[nbad++] = foreign_names[f];
            }
            for (int b = 0; b < nbad; b++) {
                void *h[NKINDS];
                for (int k = 0; k < NKINDS; k++) h[k] = live_of(&w, k);
                h[kind] = bad[b];
                AdaptimpStatus s;
                int ok = call_entry(e, h, &s);
                ok = ok && world_intact(&w, 0, 0) && world_intact(&after, 0, 0);
                snprintf(what, sizeof what, "%s, %s argument: %s", ENTRIES[e].name,
                         KIND_NAMES[kind], bad_names[b]);
                T.cases++;
                if (!ok) {
                    T.wrong++;
                    note("%s: not refused as it must be (%s)", what, adaptimp_last_error());
                } else {
                    T.clear++;
                }
            }
        }
    }
    /* The live ones still step. */
    double q[2], dq[2], te[2];
    inputs(0, q, dq, te);
    AdaptimpCommand c;
    const AdaptimpStatus s = adaptimp_step(w.ctrl, w.state, 2, q, dq, te, NULL, &c);
    outcome("the live world steps after every forged call", ACCEPT, s,
            c.n == 2 && world_intact(&w, 1, 0));
    munmap(pages, (size_t)page);
    close_world(&after);
    close_world(&w);
}

/* ---- The driver. ---- */

typedef struct {
    const char *name;
    void (*run)(void);
} Category;

static const Category CATEGORIES[] = {
    {"parameters", construction}, {"steps and fallbacks", steps}, {"snapshots", snapshots},
    {"handles and buffers", handles}, {"chains", chains},        {"Cartesian", cartesian},
    {"forged handles", forged},       {"postures, axes, orbits", postures},
    {"robot descriptions", descriptions},
};

int main(void) {
    const size_t count = sizeof CATEGORIES / sizeof CATEGORIES[0];
    Tally all;
    memset(&all, 0, sizeof all);
    printf("| surface | cases | accepted | clear | crash | hang | wrong | false_refusal |\n");
    printf("|---|---:|---:|---:|---:|---:|---:|---:|\n");
    Tally tallies[16];
    for (size_t i = 0; i < count; i++) {
        int fd[2];
        if (pipe(fd) != 0) return 2;
        fflush(stdout);
        pid_t pid = fork();
        if (pid == 0) {
            close(fd[0]);
            memset(&T, 0, sizeof T);
            snprintf(T.name, sizeof T.name, "%s", CATEGORIES[i].name);
            alarm(CATEGORY_SECONDS);
            CATEGORIES[i].run();
            if (write(fd[1], &T, sizeof T) != (ssize_t)sizeof T) _exit(2);
            _exit(0);
        }
        close(fd[1]);
        Tally t;
        memset(&t, 0, sizeof t);
        const ssize_t got = read(fd[0], &t, sizeof t);
        close(fd[0]);
        int status = 0;
        waitpid(pid, &status, 0);
        snprintf(t.name, sizeof t.name, "%s", CATEGORIES[i].name);
        if (WIFSIGNALED(status) && WTERMSIG(status) == SIGALRM) {
            t.hang++;
        } else if (got != (ssize_t)sizeof t || !WIFEXITED(status) || WEXITSTATUS(status) != 0) {
            t.crash++;
        }
        tallies[i] = t;
        printf("| %s | %ld | %ld | %ld | %ld | %ld | %ld | %ld |\n", t.name, t.cases, t.accepted,
               t.clear, t.crash, t.hang, t.wrong, t.false_refusal);
        all.cases += t.cases;
        all.accepted += t.accepted;
        all.clear += t.clear;
        all.crash += t.crash;
        all.hang += t.hang;
        all.wrong += t.wrong;
        all.false_refusal += t.false_refusal;
    }
    printf("| **all** | **%ld** | **%ld** | **%ld** | **%ld** | **%ld** | **%ld** | **%ld** |\n",
           all.cases, all.accepted, all.clear, all.crash, all.hang, all.wrong, all.false_refusal);
    for (size_t i = 0; i < count; i++)
        for (int k = 0; k < tallies[i].notes; k++) printf("- %s: %s\n", tallies[i].name, tallies[i].note[k]);
    return all.crash || all.hang || all.wrong || all.false_refusal ? 1 : 0;
}
