/* Read an arm from a URDF in C: the core reads the file, finds the arm by the
 * one rule Python and Rust use (SPEC §21), and hands back its chain.
 *
 *   16_read_urdf [PATH] [--tip LINK] [--fix JOINT]...   the arm of a URDF file
 *   16_read_urdf                                         the arm of the URDF text below
 *   16_read_urdf --errors                                the refusals, with their messages
 *
 * Prints n, each joint's limits, effort and drive terms, and the tip's pose
 * at q = 0 (the mirrors: examples/16_read_urdf.rs and .py). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "adaptimp.h"

/* A 3-joint arm holding a gripper: a driven jaw that a finger mimics (held
 * by the rule: a gripper's drive), and a tool frame. */
static const char *URDF =
    "<robot name='demo'>"
    "<link name='base'/>"
    "<link name='upper'><inertial><origin xyz='0.15 0 0'/><mass value='2'/>"
    "<inertia ixx='0.01' ixy='0' ixz='0' iyy='0.02' iyz='0' izz='0.02'/></inertial></link>"
    "<link name='fore'><inertial><origin xyz='0.1 0 0'/><mass value='1'/>"
    "<inertia ixx='0.01' ixy='0' ixz='0' iyy='0.01' iyz='0' izz='0.01'/></inertial></link>"
    "<link name='hand'><inertial><mass value='0.3'/>"
    "<inertia ixx='1e-4' ixy='0' ixz='0' iyy='1e-4' iyz='0' izz='1e-4'/></inertial></link>"
    "<link name='tool'/><link name='jaw'/><link name='finger'/>"
    "<joint name='shoulder' type='revolute'><parent link='base'/><child link='upper'/>"
    "<origin xyz='0 0 0.1'/><axis xyz='0 0 1'/>"
    "<limit lower='-3' upper='3' effort='20' velocity='2'/><dynamics damping='0.5'/></joint>"
    "<joint name='elbow' type='revolute'><parent link='upper'/><child link='fore'/>"
    "<origin xyz='0.3 0 0'/><axis xyz='0 1 0'/>"
    "<limit lower='-2' upper='2' effort='10' velocity='2'/></joint>"
    "<joint name='wrist' type='continuous'><parent link='fore'/><child link='hand'/>"
    "<origin xyz='0.2 0 0'/><axis xyz='1 0 0'/></joint>"
    "<joint name='flange' type='fixed'><parent link='hand'/><child link='tool'/>"
    "<origin xyz='0.05 0 0'/></joint>"
    "<joint name='jaw_joint' type='revolute'><parent link='hand'/><child link='jaw'/>"
    "<axis xyz='0 0 1'/><limit lower='0' upper='1' effort='1' velocity='1'/></joint>"
    "<joint name='finger_joint' type='revolute'><parent link='hand'/><child link='finger'/>"
    "<axis xyz='0 0 1'/><limit lower='-1' upper='0' effort='1' velocity='1'/>"
    "<mimic joint='jaw_joint' multiplier='-1'/></joint>"
    "</robot>";

static int read_arm(const char *source, const char *tip, const char *const *fix, size_t nfix) {
    AdaptimpChain *chain = NULL;
    AdaptimpArmInfo info;
    AdaptimpStatus s = adaptimp_chain_from_urdf(source, tip, fix, nfix, &chain, &info);
    if (s != ADAPTIMP_STATUS_OK) {
        fprintf(stderr, "error %d: %s\n", (int)s, adaptimp_last_error());
        return 1;
    }
    printf("n = %zu\n", info.n);
    for (size_t i = 0; i < info.n; i++) {
        printf("joint %zu: %s, limits [%g, %g], effort %g, damping %g, friction %g\n", i,
               info.prismatic[i] ? "prismatic" : "revolute", info.lower[i], info.upper[i],
               info.effort[i], info.damping[i], info.friction[i]);
    }
    double q[ADAPTIMP_MAX_JOINTS] = {0};
    AdaptimpTip t;
    s = adaptimp_chain_tip(chain, info.n, q, NULL, &t);
    if (s != ADAPTIMP_STATUS_OK) {
        fprintf(stderr, "error %d: %s\n", (int)s, adaptimp_last_error());
        adaptimp_chain_free(chain);
        return 1;
    }
    printf("tip at q = 0: %.17g %.17g %.17g\n", t.position[0], t.position[1], t.position[2]);
    adaptimp_chain_free(chain);
    return 0;
}

/* Each refusal: its status and its message, which names the file and the element. */
static int errors(void) {
    struct {
        const char *source, *tip, *expect;
        AdaptimpStatus status;
    } cases[] = {
        {"no/such/file.urdf", NULL, "cannot read the URDF 'no/such/file.urdf'",
         ADAPTIMP_STATUS_INVALID_CONFIG},
        {"<robot name='x' xmlns:xacro='http://www.ros.org/wiki/xacro'>"
         "<xacro:property name='l' value='1'/></robot>",
         NULL, "is xacro, not a URDF", ADAPTIMP_STATUS_INVALID_CONFIG},
        {"<robot name='x'><link name='a'/><joint name='j' type='revolute'>"
         "<parent link='a'/><child link='b'/></joint></robot>",
         NULL, "joint 'j' names the child link 'b', which is not declared",
         ADAPTIMP_STATUS_INVALID_CONFIG},
        {NULL, "nowhere", "tip= 'nowhere' is neither a link nor a frame",
         ADAPTIMP_STATUS_INVALID_CONFIG},
        {NULL, NULL, "source is NULL", ADAPTIMP_STATUS_NULL_POINTER},
    };
    int failed = 0;
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        const char *source = cases[i].source;
        if (source == NULL && cases[i].tip != NULL) source = URDF;
        AdaptimpChain *chain = NULL;
        AdaptimpStatus s = adaptimp_chain_from_urdf(source, cases[i].tip, NULL, 0, &chain, NULL);
        const char *message = adaptimp_last_error();
        int ok = s == cases[i].status && strstr(message, cases[i].expect) != NULL && !chain;
        printf("%s status %d: %s\n", ok ? "ok  " : "FAIL", (int)s, message);
        failed += !ok;
    }
    /* An unknown joint in fix, named. */
    const char *bad[] = {"nope"};
    AdaptimpChain *chain = NULL;
    AdaptimpStatus s = adaptimp_chain_from_urdf(URDF, NULL, bad, 1, &chain, NULL);
    int ok = s == ADAPTIMP_STATUS_INVALID_CONFIG &&
             strstr(adaptimp_last_error(), "fix= names joints it does not have: ['nope']");
    printf("%s status %d: %s\n", ok ? "ok  " : "FAIL", (int)s, adaptimp_last_error());
    failed += !ok;
    return failed ? 1 : 0;
}

int main(int argc, char **argv) {
    const char *source = URDF, *tip = NULL;
    const char *fix[16];
    size_t nfix = 0;
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--errors") == 0) return errors();
        if (strcmp(argv[i], "--tip") == 0 && i + 1 < argc) {
            tip = argv[++i];
        } else if (strcmp(argv[i], "--fix") == 0 && i + 1 < argc && nfix < 16) {
            fix[nfix++] = argv[++i];
        } else {
            source = argv[i];
        }
    }
    return read_arm(source, tip, nfix ? fix : NULL, nfix);
}
