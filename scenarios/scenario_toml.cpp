#include "scenarios/scenario_toml.h"

#include <fmt/format.h>

namespace bouncecheck {

std::string scenario_toml(const Scenario& s) {
    auto vec = [&](const Vec3& v) {
        std::string out = "[";
        for (int i = 0; i < s.dim; ++i) out += fmt::format("{}{:.17g}", i ? ", " : "", v[i]);
        return out + "]";
    };
    return fmt::format(
        "name = \"{}\"\ndescription = \"{}\"\n\n[room]\nsize = {}\n\n[ball]\nradius = {:.17g}\nposition = {}\n"
        "velocity = {}\n\n[world]\ngravity = {}\n\n[damping]\nnormal = {:.17g}\ntangential = {:.17g}\n\n"
        "[run]\ndt = {:.17g}\nduration = {:.17g}\n",
        s.name, s.description, vec(s.room), s.radius, vec(s.position), vec(s.velocity), vec(s.gravity), s.alpha,
        s.beta, s.dt, s.duration);
}

}  // namespace bouncecheck
