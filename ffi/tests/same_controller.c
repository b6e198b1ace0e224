/* The controller the C ABI builds from given parameters, stepped on given
 * inputs: tests/test_ffi.py builds the same controller from the same
 * parameters in Python and compares the torques bit for bit (one builder
 * serves both fronts).
 *
 *   same_controller N LAW PRESET [NAME=V1,V2,...]...
 *   same_controller N LAW rule [FIELD=V1,V2,...]...
 *
 * LAW is pd, sf or of; PRESET paper or robot. Each NAME is a parameter of
 * the schema (a real, or one value per joint or per network), or `centers`
 * (L rows of 4N reals, flattened) and `widths2` (4N reals). With `rule`,
 * the parameters are the rule's (adaptimp_params_suggest_tuning) and each
 * FIELD one of AdaptimpTuning's (`inertia` K n × n matrices, flattened, K
 * = `inertia_samples`; `path` and `orbit` rows flattened, their row counts
 * taken from their lengths; `coupling` 0, 1, 2 for default, diagonal,
 * shaped; the flags 0 or 1). Then each line
 * of stdin holds one step's q, dq and tau_e (3N reals); each line of stdout
 * the step's sat(τ) and τ (2N reals, %.17g: every digit), or "status S: the
 * message" for a refused one. Exits 2 if the controller is refused. */
#include "adaptimp.h"

#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { REAL, JOINT, THREE, COUNT };

/* The numeric fields of AdaptimpParams by their schema names. */
static const struct {
    const char *name;
    size_t offset;
    int kind;
} FIELDS[] = {
    {"Ts", offsetof(AdaptimpParams, ts), REAL},
    {"delay", offsetof(AdaptimpParams, delay), COUNT},
    {"K1", offsetof(AdaptimpParams, k1), JOINT},
    {"Kp", offsetof(AdaptimpParams, kp), JOINT},
    {"Kzeta", offsetof(AdaptimpParams, kzeta), JOINT},
    {"inertia", offsetof(AdaptimpParams, inertia), JOINT},
    {"rho", offsetof(AdaptimpParams, rho), REAL},
    {"mu", offsetof(AdaptimpParams, mu), REAL},
    {"kr", offsetof(AdaptimpParams, kr), JOINT},
    {"phi", offsetof(AdaptimpParams, phi), REAL},
    {"kappa", offsetof(AdaptimpParams, kappa), REAL},
    {"gamma", offsetof(AdaptimpParams, gamma), THREE},
    {"sigma", offsetof(AdaptimpParams, sigma), THREE},
    {"eps", offsetof(AdaptimpParams, eps), REAL},
    {"lam1", offsetof(AdaptimpParams, lam1), JOINT},
    {"tau_max", offsetof(AdaptimpParams, tau_max), JOINT},
    {"Dd", offsetof(AdaptimpParams, dd), JOINT},
    {"Cd", offsetof(AdaptimpParams, cd), JOINT},
    {"Gd", offsetof(AdaptimpParams, gd), JOINT},
    {"eta2", offsetof(AdaptimpParams, eta2), REAL},
    {"xc_offset", offsetof(AdaptimpParams, xc_offset), JOINT},
    {"xc_sin", offsetof(AdaptimpParams, xc_sin), JOINT},
    {"xc_cos", offsetof(AdaptimpParams, xc_cos), JOINT},
    {"xc_omega", offsetof(AdaptimpParams, xc_omega), JOINT},
    {"fallback_damping", offsetof(AdaptimpParams, fallback_damping), JOINT},
};

/* The rule's inputs from FIELD=V1,V2,... arguments into `p`; 0, or 2 on
 * an unknown field or a refusal (the message on stderr). */
static int suggest(AdaptimpParams *p, size_t n, AdaptimpLaw law, int argc, char **argv);

/* The reals of `text`, separated by commas or blanks, into `out` (at most
 * `max`); their number. */
static size_t reals(const char *text, double *out, size_t max) {
    size_t k = 0;
    while (k < max) {
        char *end;
        const double v = strtod(text, &end);
        if (end == text) break;
        out[k++] = v;
        text = end;
        while (*text == ',' || *text == ' ') text++;
    }
    return k;
}

int main(int argc, char **argv) {
    if (argc < 4) {
        fprintf(stderr, "usage: %s N LAW PRESET [NAME=V1,V2,...]...\n", argv[0]);
        return 2;
    }
    const size_t n = (size_t)strtoul(argv[1], NULL, 10);
    const AdaptimpLaw law = strcmp(argv[2], "pd") == 0   ? ADAPTIMP_LAW_PD
                            : strcmp(argv[2], "sf") == 0 ? ADAPTIMP_LAW_STATE_FEEDBACK
                                                         : ADAPTIMP_LAW_OUTPUT_FEEDBACK;
    const AdaptimpPreset preset =
        strcmp(argv[3], "paper") == 0 ? ADAPTIMP_PRESET_PAPER : ADAPTIMP_PRESET_ROBOT;
    AdaptimpParams p;
    if (strcmp(argv[3], "rule") == 0) {
        if (suggest(&p, n, law, argc - 4, argv + 4) != 0) return 2;
        argc = 4;
    } else if (adaptimp_params_default(&p, n, law, preset) != ADAPTIMP_STATUS_OK) {
        fprintf(stderr, "%s\n", adaptimp_last_error());
        return 2;
    }
    static double centers[4096 * 4 * ADAPTIMP_MAX_JOINTS], widths2[4 * ADAPTIMP_MAX_JOINTS];
    for (int a = 4; a < argc; a++) {
        char *eq = strchr(argv[a], '=');
        if (!eq) return 2;
        *eq = '\0';
        const char *name = argv[a], *values = eq + 1;
        if (strcmp(name, "centers") == 0) {
            p.centers = centers;
            p.nodes = reals(values, centers, sizeof centers / sizeof centers[0]) / (4 * n);
            continue;
        }
        if (strcmp(name, "widths2") == 0) {
            reals(values, widths2, 4 * n);
            p.widths2 = widths2;
            continue;
        }
        size_t f = 0;
        while (f < sizeof FIELDS / sizeof FIELDS[0] && strcmp(FIELDS[f].name, name) != 0) f++;
        if (f == sizeof FIELDS / sizeof FIELDS[0]) {
            fprintf(stderr, "unknown parameter %s\n", name);
            return 2;
        }
        char *at = (char *)&p + FIELDS[f].offset;
        double v[ADAPTIMP_MAX_JOINTS];
        const size_t k = reals(values, v, ADAPTIMP_MAX_JOINTS);
        if (FIELDS[f].kind == COUNT) {
            *(size_t *)(void *)at = (size_t)v[0];
        } else {
            memcpy(at, v, k * sizeof(double));
        }
    }
    AdaptimpController *ctrl = NULL;
    AdaptimpState *state = NULL;
    if (adaptimp_controller_new(&p, &ctrl) != ADAPTIMP_STATUS_OK ||
        adaptimp_state_new(ctrl, &state) != ADAPTIMP_STATUS_OK) {
        fprintf(stderr, "%s\n", adaptimp_last_error());
        adaptimp_controller_free(ctrl);
        return 2;
    }
    double in[3 * ADAPTIMP_MAX_JOINTS];
    char line[4096];
    while (fgets(line, sizeof line, stdin)) {
        if (reals(line, in, 3 * n) != 3 * n) break;
        AdaptimpCommand cmd;
        const AdaptimpStatus s = adaptimp_step(ctrl, state, n, in, in + n, in + 2 * n, NULL, &cmd);
        if (s != ADAPTIMP_STATUS_OK) {
            printf("status %d: %s\n", (int)s, adaptimp_last_error());
            continue;
        }
        for (size_t i = 0; i < n; i++) printf("%.17g ", cmd.tau_sat[i]);
        for (size_t i = 0; i < n; i++) printf(i + 1 < n ? "%.17g " : "%.17g\n", cmd.tau[i]);
    }
    adaptimp_state_free(state);
    adaptimp_controller_free(ctrl);
    return 0;
}

static int suggest(AdaptimpParams *p, size_t n, AdaptimpLaw law, int argc, char **argv) {
    static double inertia[64 * ADAPTIMP_MAX_JOINTS * ADAPTIMP_MAX_JOINTS],
        tau_max[ADAPTIMP_MAX_JOINTS], path[512 * 3 * ADAPTIMP_MAX_JOINTS],
        gravity[ADAPTIMP_MAX_JOINTS], damping[ADAPTIMP_MAX_JOINTS],
        orbit[512 * ADAPTIMP_MAX_JOINTS], centers[ADAPTIMP_SUGGEST_MAX_NODES * 4 * ADAPTIMP_MAX_JOINTS],
        widths2[4 * ADAPTIMP_MAX_JOINTS];
    AdaptimpTuning t;
    if (adaptimp_tuning_init(&t, law, inertia, tau_max, 1e-3) != ADAPTIMP_STATUS_OK) return 2;
    for (int a = 0; a < argc; a++) {
        char *eq = strchr(argv[a], '=');
        if (!eq) return 2;
        *eq = '\0';
        const char *name = argv[a], *values = eq + 1;
        double v[1];
        if (strcmp(name, "inertia") == 0) {
            reals(values, inertia, sizeof inertia / sizeof inertia[0]);
        } else if (strcmp(name, "tau_max") == 0) {
            reals(values, tau_max, n);
        } else if (strcmp(name, "path") == 0) {
            t.path = path;
            t.rows = reals(values, path, sizeof path / sizeof path[0]) / (3 * n);
        } else if (strcmp(name, "gravity") == 0) {
            t.gravity = gravity;
            reals(values, gravity, n);
        } else if (strcmp(name, "damping") == 0) {
            t.damping = damping;
            reals(values, damping, n);
        } else if (strcmp(name, "orbit") == 0) {
            t.orbit = orbit;
            t.orbit_rows = reals(values, orbit, sizeof orbit / sizeof orbit[0]) / n;
        } else if (reals(values, v, 1) != 1) {
            fprintf(stderr, "no value for %s\n", name);
            return 2;
        } else if (strcmp(name, "inertia_samples") == 0) {
            t.inertia_samples = (size_t)v[0];
        } else if (strcmp(name, "Ts") == 0) {
            t.ts = v[0];
        } else if (strcmp(name, "delay") == 0) {
            t.delay = (size_t)v[0];
        } else if (strcmp(name, "period") == 0) {
            t.period = v[0];
        } else if (strcmp(name, "coupling") == 0) {
            const AdaptimpCoupling c[] = {ADAPTIMP_COUPLING_DEFAULT, ADAPTIMP_COUPLING_DIAGONAL,
                                          ADAPTIMP_COUPLING_SHAPED};
            t.coupling = c[(unsigned)v[0] % 3u];
        } else if (strcmp(name, "resolve") == 0) {
            t.resolve = v[0] != 0.0;
        } else if (strcmp(name, "critical") == 0) {
            t.critical = v[0] != 0.0;
        } else if (strcmp(name, "weightless") == 0) {
            t.weightless = v[0] != 0.0;
        } else {
            fprintf(stderr, "unknown field %s\n", name);
            return 2;
        }
    }
    if (adaptimp_params_suggest_tuning(p, n, &t, centers, widths2) != ADAPTIMP_STATUS_OK) {
        fprintf(stderr, "%s\n", adaptimp_last_error());
        return 2;
    }
    return 0;
}
