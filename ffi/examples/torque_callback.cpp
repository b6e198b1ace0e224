// adaptimp in the shape of a 1 kHz torque callback (a libfranka or
// ros2_control update()): a class that owns the controller and its state,
// `update(q, dq, tau_ext) -> tau`, and an error path that never leaves the
// robot without a command.
#include "adaptimp.h"

#include <array>
#include <cmath>
#include <cstdio>
#include <memory>
#include <stdexcept>
#include <string>

namespace {

constexpr std::size_t kJoints = 2;
using Joints = std::array<double, kJoints>;

// Owns an adaptimp controller and its state; move-only.
class AdaptiveImpedance {
  public:
    AdaptiveImpedance(AdaptimpPreset preset, AdaptimpLaw law) {
        AdaptimpController* ctrl = nullptr;
        check(adaptimp_controller_new_preset(preset, law, &ctrl), "controller");
        ctrl_.reset(ctrl);
        AdaptimpState* state = nullptr;
        check(adaptimp_state_new(ctrl_.get(), &state), "state");
        state_.reset(state);
    }

    // One step of the 1 kHz loop: measured joint positions (rad), velocities
    // (rad/s) and external torque (N m) in, the torque to apply (N m) out.
    // adaptimp_step writes cmd on every status (the table at adaptimp_step in
    // adaptimp.h): with cmd.n == kJoints a controller answered, and
    // cmd.tau_sat is the torque to apply: the step's, or after a refused step
    // its configured fallback (by default the last applied torque, held), so
    // the real-time loop keeps running, the error is counted, and a
    // supervisor reads error(). cmd.n == 0 means no controller could be
    // asked (a NULL or freed handle: a programming error): there is no
    // torque to apply, and the loop is stopped (libfranka stops the robot
    // when its control callback throws).
    Joints update(const Joints& q, const Joints& dq, const Joints& tau_ext) {
        AdaptimpCommand cmd;
        const AdaptimpStatus s = adaptimp_step(ctrl_.get(), state_.get(), kJoints, q.data(),
                                               dq.data(), tau_ext.data(), nullptr, &cmd);
        if (s != ADAPTIMP_STATUS_OK) {
            ++errors_;
            error_ = adaptimp_last_error();
        }
        if (cmd.n != kJoints)
            throw std::logic_error("adaptimp: no controller to ask (" + error_ + ")");
        Joints tau{};
        for (std::size_t i = 0; i < kJoints; ++i) tau[i] = cmd.tau_sat[i];
        return tau;
    }

    double period() const { return adaptimp_controller_period(ctrl_.get()); }
    unsigned errors() const { return errors_; }
    const std::string& error() const { return error_; }

  private:
    static void check(AdaptimpStatus s, const char* what) {
        if (s != ADAPTIMP_STATUS_OK)
            throw std::runtime_error(std::string(what) + ": " + adaptimp_last_error());
    }
    struct FreeController {
        void operator()(AdaptimpController* c) const { adaptimp_controller_free(c); }
    };
    struct FreeState {
        void operator()(AdaptimpState* s) const { adaptimp_state_free(s); }
    };
    std::unique_ptr<AdaptimpController, FreeController> ctrl_;
    std::unique_ptr<AdaptimpState, FreeState> state_;
    unsigned errors_ = 0;
    std::string error_;
};

}  // namespace

int main() {
    // The robot scenario: Ts = 1 ms, the hardened options.
    AdaptiveImpedance controller(ADAPTIMP_PRESET_ROBOT, ADAPTIMP_LAW_STATE_FEEDBACK);
    // A stand-in for the robot: a unit-inertia double integrator per joint.
    Joints q{0.25, -0.05}, dq{0.0, 0.0};
    const Joints no_contact{0.0, 0.0};
    const double ts = controller.period();
    Joints tau{};
    for (int k = 0; k < 2000; ++k) {
        tau = controller.update(q, dq, no_contact);
        for (std::size_t i = 0; i < kJoints; ++i) {
            dq[i] += ts * (tau[i] - 2.0 * dq[i]);
            q[i] += ts * dq[i];
        }
    }
    std::printf("after 2 s: q = [%.4f, %.4f] rad, tau = [%.3f, %.3f] N m, errors %u\n", q[0],
                q[1], tau[0], tau[1], controller.errors());
    // The error path: a NaN from a broken sensor is refused, the fallback (the
    // last applied torque, held) returned.
    const Joints broken{std::nan(""), -0.05};
    const Joints held = controller.update(broken, dq, no_contact);
    std::printf("with a NaN position: tau = [%.3f, %.3f] N m held, error: %s\n", held[0], held[1],
                controller.error().c_str());
    if (controller.errors() != 1 || held != tau) return 1;
    // A configuration error throws at construction.
    try {
        AdaptimpParams p;
        if (adaptimp_params_default(&p, 2, ADAPTIMP_LAW_STATE_FEEDBACK, ADAPTIMP_PRESET_ROBOT) !=
            ADAPTIMP_STATUS_OK)
            return 1;
        p.ts = -1e-3;
        AdaptimpController* c = nullptr;
        if (adaptimp_controller_new(&p, &c) != ADAPTIMP_STATUS_OK)
            throw std::runtime_error(adaptimp_last_error());
        adaptimp_controller_free(c);
        return 1;
    } catch (const std::runtime_error& e) {
        std::printf("invalid parameters refused: %s\n", e.what());
    }
    return 0;
}
