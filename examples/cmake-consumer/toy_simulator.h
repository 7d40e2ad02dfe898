// A simulator of a program's own, for bouncecheck's C++ API: semi-implicit
// (velocity-first) Euler with the law's per-contact damping, the algorithm of
// examples/external/semi_implicit_euler.py, run in this process rather than
// through the external protocol.
#pragma once

#include <bouncecheck/bouncecheck.h>

#include <optional>
#include <string>
#include <string_view>

namespace toy {

class SemiImplicitEuler final : public bouncecheck::Simulator {
public:
    // `alpha_override`: when set, this normal damping replaces the
    // scenario's alpha, which makes a deliberately wrong simulator (the
    // tests' proof that the law check can fail). `name`: the simulator's row
    // in the harness's tables and reports; not "reference" or "exact".
    explicit SemiImplicitEuler(std::optional<double> alpha_override = std::nullopt,
                               std::string name = "semi-implicit");

    std::string_view name() const override { return name_; }
    std::string_view description() const override { return description_; }
    bouncecheck::RunOutcome run(const bouncecheck::Scenario& s, bouncecheck::RunSink& sink) const override;

private:
    std::optional<double> alpha_override_;
    std::string name_;
    std::string description_;
};

}  // namespace toy
