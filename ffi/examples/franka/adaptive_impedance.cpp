// adaptimp's adaptive impedance in libfranka's own 1 kHz torque callback, through
// adaptimp's C ABI (SPEC §22; docs/franka.md shows the same loop in Python).
//
// The controller: the rule of SPEC §18 (adaptimp_params_suggest) from the robot's
// own mass matrix at the start, for libfranka's one period of delay and an arm
// without gravity: the robot adds its
// model's gravity torque to every command (SPEC (22.1)), so none is given to the
// rule and the controller never commands it. Its torque rate is libfranka's
// kMaxTorqueRate, 1 N m a 1 ms cycle (SPEC (22.3)): the controller limits it
// itself, before its saturation, so libfranka's own limiter and low-pass filter
// are off (the torque the learning sees is the one sent). The task: the
// adaptive joint impedance holds the arm where it stands, the robot's wrench
// estimate O_F_ext_hat_K fed back as τe = Jᵀ F (push the arm: it yields as the
// impedance says and learns what holds it). A step the controller refuses
// returns its fallback (the last torque, held); the callback then ends the
// motion with it. Ctrl-C or the user stop ends the motion on the robot's side.
//
//   adaptive_impedance <robot-ip> [seconds]   (default 10 s)
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <optional>  // before libfranka 0.21's robot.h, which uses std::optional unincluded
#include <stdexcept>
#include <string>
#include <vector>

#include <franka/exception.h>
#include <franka/model.h>
#include <franka/robot.h>

#include "adaptimp.h"

namespace {

constexpr std::size_t kJoints = 7;
// The most centres adaptimp_params_suggest writes (SPEC §18: 16 … 256).
constexpr std::size_t kMaxNodes = 256;
// libfranka applies a torque at the next 1 ms tick: one period of delay (SPEC (18.11)).
constexpr std::size_t kDelay = 1;
// libfranka's kMaxTorqueRate (N m/s) over one 1 ms cycle.
constexpr double kRatePerCycle = 1000.0 * 1e-3;
constexpr std::array<double, kJoints> kTauMax{{87, 87, 87, 87, 12, 12, 12}};

void check(AdaptimpStatus s, const char* what) {
    if (s != ADAPTIMP_STATUS_OK)
        throw std::runtime_error(std::string(what) + ": " + adaptimp_last_error());
}

struct FreeController {
    void operator()(AdaptimpController* c) const { adaptimp_controller_free(c); }
};
struct FreeState {
    void operator()(AdaptimpState* s) const { adaptimp_state_free(s); }
};

}  // namespace

int main(int argc, char** argv) {
    if (argc < 2) {
        std::fprintf(stderr, "usage: %s <robot-ip> [seconds]\n", argv[0]);
        return 2;
    }
    const double duration = argc > 2 ? std::atof(argv[2]) : 10.0;
    try {
        // Real-time scheduling where the kernel has it (libfranka's own test);
        // elsewhere (a simulator on a laptop) the loop runs without it.
        std::ifstream rt("/sys/kernel/realtime");
        int realtime = 0;
        rt >> realtime;
        franka::Robot robot(argv[1], realtime == 1 ? franka::RealtimeConfig::kEnforce
                                                   : franka::RealtimeConfig::kIgnore);
        // Beyond these external torques and forces the robot stops by a reflex.
        robot.setCollisionBehavior({{20, 20, 18, 18, 16, 14, 12}}, {{20, 20, 18, 18, 16, 14, 12}},
                                   {{20, 20, 20, 25, 25, 25}}, {{20, 20, 20, 25, 25, 25}});
        franka::Model model = robot.loadModel();
        const franka::RobotState start = robot.readOnce();

        // The rule from the robot's mass matrix where the arm stands (column-major
        // and symmetric: row-major as well), the task a hold of that posture.
        const std::array<double, 49> mass = model.mass(start);
        std::vector<double> path;
        for (int row = 0; row < 100; ++row) {
            for (double v : start.q) path.push_back(v);
            for (std::size_t i = 0; i < 2 * kJoints; ++i) path.push_back(0.0);
        }
        std::vector<double> centers(kMaxNodes * 4 * kJoints), widths2(4 * kJoints);
        AdaptimpParams params;
        check(adaptimp_params_suggest(&params, kJoints, ADAPTIMP_LAW_STATE_FEEDBACK, mass.data(),
                                      kTauMax.data(), 1e-3, kDelay, path.data(), 100, 1.0, nullptr,
                                      centers.data(), widths2.data()),
              "the rule");
        params.impedance = ADAPTIMP_IMPEDANCE_EXTERNAL;
        for (std::size_t i = 0; i < kJoints; ++i) params.tau_rate_max[i] = kRatePerCycle;
        AdaptimpController* c = nullptr;
        check(adaptimp_controller_new(&params, &c), "the controller");
        std::unique_ptr<AdaptimpController, FreeController> ctrl(c);
        AdaptimpState* s = nullptr;
        check(adaptimp_state_new(ctrl.get(), &s), "its state");
        std::unique_ptr<AdaptimpState, FreeState> state(s);
        // What the robot holds the arm with now (gravity aside): the first command
        // continues it, and the rate limit moves from it (no step in torque).
        const franka::RobotState held = robot.readOnce();
        check(adaptimp_state_take_over(ctrl.get(), state.get(), held.tau_J_d.data(), kJoints),
              "taking over the robot's torque");

        AdaptimpSetpoint hold{};
        for (std::size_t i = 0; i < kJoints; ++i) hold.x[i] = start.q[i];
        double time = 0.0, drift = 0.0;
        unsigned refused = 0;
        std::string error;
        robot.control(
            [&](const franka::RobotState& rs, franka::Duration period) -> franka::Torques {
                // The clock of the measurement: a late cycle advances it by its duration.
                time += period.toSec();
                // τe = Jᵀ F, F what the robot exerts on its environment at K.
                const std::array<double, 42> j = model.zeroJacobian(franka::Frame::kStiffness, rs);
                std::array<double, kJoints> tau_e{};
                for (std::size_t i = 0; i < kJoints; ++i)
                    for (std::size_t r = 0; r < 6; ++r) tau_e[i] += j[6 * i + r] * rs.O_F_ext_hat_K[r];
                AdaptimpCommand cmd;
                const AdaptimpStatus st = adaptimp_step(ctrl.get(), state.get(), kJoints,
                                                        rs.q.data(), rs.dq.data(), tau_e.data(),
                                                        &hold, &cmd);
                for (std::size_t i = 0; i < kJoints; ++i)
                    drift = std::max(drift, std::abs(rs.q[i] - start.q[i]));
                if (cmd.n != kJoints)  // no controller to ask: libfranka stops the robot
                    throw std::logic_error(std::string("adaptimp: ") + adaptimp_last_error());
                franka::Torques tau{{cmd.tau_sat[0], cmd.tau_sat[1], cmd.tau_sat[2],
                                     cmd.tau_sat[3], cmd.tau_sat[4], cmd.tau_sat[5],
                                     cmd.tau_sat[6]}};
                if (st != ADAPTIMP_STATUS_OK) {  // the fallback, held: end the motion with it
                    ++refused;
                    error = adaptimp_last_error();
                    return franka::MotionFinished(tau);
                }
                return time >= duration ? franka::MotionFinished(tau) : tau;
            },
            /*limit_rate=*/false, /*cutoff_frequency=*/franka::kMaxCutoffFrequency);
        if (refused) {
            std::fprintf(stderr, "the controller refused a step: %s\n", error.c_str());
            return 1;
        }
        std::printf("held %.1f s, every joint within %.2g rad of where it stood\n", time, drift);
    } catch (const franka::Exception& e) {
        std::fprintf(stderr, "libfranka: %s\n", e.what());
        return 1;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "%s\n", e.what());
        return 1;
    }
    return 0;
}
