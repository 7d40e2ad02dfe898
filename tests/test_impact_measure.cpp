// The damping measured at the impact instant: exact to round-off for the
// reference and for an event-driven simulator at any dt and g, and the
// tangential verdict that tells beta = 0.99 from no loss and from 0.97.
#include "metrics/summary.h"
#include "scenarios/loader.h"
#include "simulators/document_clock.h"
#include "tests/support/cli.h"
#include "verdicts/verdicts.h"

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <unistd.h>

namespace bouncecheck {
namespace {

namespace fs = std::filesystem;
using test::bouncecheck;
using test::CliResult;

// A ball falling onto the floor plane z = 0 (its centre's wall plane),
// bounced by the law at t_hit inside the step [0, dt]: samples at 0 and dt.
struct Bounce {
    State before, after;
    double t_hit;
};
Bounce law_bounce(double g, double dt, double fraction, double alpha, double beta, double vx) {
    const double t_hit = fraction * dt, v_hit = 1.3;  // speed into the floor at the impact
    Bounce b;
    b.t_hit = t_hit;
    // Back from the impact: z(t) = v_hit (t_hit - t) - g/2 (t_hit - t)^2 above the plane.
    const double u = t_hit;
    b.before.t = 0;
    b.before.p = Vec3(0.2, 0, v_hit * u - 0.5 * g * u * u);
    b.before.v = Vec3(vx, 0, -(v_hit - g * u));
    const double w = dt - t_hit, out = alpha * v_hit;
    b.after.t = dt;
    b.after.p = Vec3(0.2 + vx * t_hit + beta * vx * w, 0, out * w - 0.5 * g * w * w);
    b.after.v = Vec3(beta * vx, 0, out - g * w);
    return b;
}

TEST(ImpactMeasure, EventDrivenImpactBetweenSamplesReadsTheLaw) {
    // The seed's scale, Earth's, and an impact early, midway and late in the step.
    for (const double g : {0.0981, 9.81}) {
        for (const double dt : {0.03, 0.01, 1.0 / 60}) {
            for (const double fraction : {0.05, 0.5, 0.95}) {
                const Bounce b = law_bounce(g, dt, fraction, 0.7, 0.99, 0.4);
                const ImpactVelocities at = impact_velocities(b.before, b.after, 2, -1, 0.0, Vec3(0, 0, -g));
                EXPECT_NEAR(at.t, b.t_hit, 1e-12) << g << " " << dt << " " << fraction;
                const ContactEvent e = measure_contact(at.t, 2, -1, at.incoming, at.outgoing, 3);
                EXPECT_NEAR(e.normal_coefficient, 0.7, 1e-12) << g << " " << dt << " " << fraction;
                EXPECT_NEAR(e.tangential_retention, 0.99, 1e-12);
                EXPECT_NEAR(e.normal_speed_in, 1.3, 1e-12);
                // What the samples alone read (the sample before plus a
                // step of gravity): off by far more than round-off.
                const ContactEvent sampled =
                    measure_contact(b.after.t, 2, -1, b.before.v + Vec3(0, 0, -g) * dt, b.after.v, 3);
                if (g == 9.81) EXPECT_GT(std::abs(sampled.normal_coefficient - 0.7), 1e-3);
            }
        }
    }
}

TEST(ImpactMeasure, SampleOnTheWallIsTheInstant) {
    // The reference's step: gravity, then the sample placed on the wall
    // with the velocity turned: the instant is that sample, the incoming
    // velocity the sample before plus the step's gravity.
    const double g = 0.0981, dt = 0.03;
    State before{0, Vec3(0.5, 0.5, 0.051), Vec3(0.1, 0, -0.3)};
    const Vec3 meets = before.v + Vec3(0, 0, -g * dt);
    State after{dt, Vec3(0.5, 0.5, 0.05), Vec3(0.99 * meets.x(), 0, -0.8 * meets.z())};
    const ImpactVelocities at = impact_velocities(before, after, 2, -1, 0.05, Vec3(0, 0, -g));
    EXPECT_EQ(at.t, dt);
    EXPECT_EQ(at.incoming, meets);
    EXPECT_EQ(at.outgoing, after.v);
}

TEST(ImpactMeasure, CeilingAndSideWallsUseTheirOwnNormal) {
    // An upper wall at x = 0.95: the ball met it midway with 0.5 m/s, no
    // gravity along x.
    const double dt = 0.02;
    State before{0, Vec3(0.95 - 0.5 * 0.01, 0.3, 0), Vec3(0.5, 0.2, 0)};
    State after{dt, Vec3(0.95 - 0.8 * 0.5 * 0.01, 0.3 + 0.2 * 0.01 + 0.198 * 0.01, 0), Vec3(-0.4, 0.198, 0)};
    const ImpactVelocities at = impact_velocities(before, after, 0, +1, 0.95, Vec3(0, 0, -9.81));
    EXPECT_NEAR(at.t, 0.01, 1e-12);
    const ContactEvent e = measure_contact(at.t, 0, +1, at.incoming, at.outgoing, 3);
    EXPECT_NEAR(e.normal_coefficient, 0.8, 1e-12);
}

// One contact with tangential motion per entry, fast enough to be measured.
SimulatorSummary with_retentions(const Scenario& s, std::initializer_list<double> retentions) {
    SimulatorSummary out;
    double t = 1;
    for (const double r : retentions)
        out.contact_events.push_back({t++, s.vertical_axis(), -1, s.alpha, r, 1000 * s.gravity.norm() * s.dt});
    return out;
}

TEST(TangentialVerdict, FailsNoLossAndThreeTimesTheLossPassesTheLaw) {
    const Scenario s = load_scenario(std::string(BOUNCECHECK_SCENARIO_DIR) + "/seed-3d.toml");
    EXPECT_TRUE(check_damping(with_retentions(s, {0.99, 0.99, 0.99}), s, {}).reproduces);
    EXPECT_TRUE(check_damping(with_retentions(s, {0.988, 0.992, 0.99}), s, {}).reproduces);
    const DampingCheck none = check_damping(with_retentions(s, {1.0, 1.0}), s, {});
    EXPECT_FALSE(none.reproduces);
    EXPECT_NEAR(none.tangential_loss_rel, 1.0, 1e-12);
    EXPECT_NE(none.verdict.find("tangential loss"), std::string::npos) << none.verdict;
    const DampingCheck triple = check_damping(with_retentions(s, {0.97, 0.97}), s, {});
    EXPECT_FALSE(triple.reproduces);
    EXPECT_NEAR(triple.tangential_loss_rel, 2.0, 1e-12);
    // No loss at all was within the absolute tolerance that used to pass it.
    EXPECT_LE(std::abs(1.0 - s.beta), kDefaultDampingTolerance);
    // The limit is a threshold key too, and tangential_abs keeps its meaning.
    ThresholdSet loose;
    loose.tangential_loss_rel = 2.5;
    const DampingCheck loosened = check_damping(with_retentions(s, {0.975, 0.975}), s, loose);
    EXPECT_TRUE(loosened.reproduces) << loosened.verdict;
    loose.tangential_abs = 0.001;
    EXPECT_FALSE(check_damping(with_retentions(s, {0.975, 0.975}), s, loose).reproduces);
    // A law without tangential loss (beta = 1) is judged on a 1% scale.
    Scenario elastic = s;
    elastic.beta = 1.0;
    EXPECT_TRUE(check_damping(with_retentions(elastic, {1.0, 0.999}), elastic, {}).reproduces);
    EXPECT_FALSE(check_damping(with_retentions(elastic, {0.99, 0.99}), elastic, {}).reproduces);
}

// ---------------------------------------------------------------- an exact event-driven simulator from outside

fs::path fresh_dir(const std::string& name) {
    const fs::path dir = fs::temp_directory_path() / ("bouncecheck-impact-" + name + "-" + std::to_string(::getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir);
    return dir;
}

std::string slurp(const fs::path& p) {
    std::ifstream in(p);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

// exact's trajectory of `scenario_text` (its impacts fall between samples),
// brought back as a recorded simulator into a run of `judged`: its damping.
nlohmann::json event_driven_damping(const fs::path& dir, const std::string& source_file, const std::string& judged) {
    const fs::path out = dir / "exact-out";
    const CliResult exported =
        bouncecheck("run " + source_file + " --engines exact --trajectories --no-timings --out " + out.string());
    EXPECT_EQ(exported.status, 0) << exported.output;
    const std::string name = load_scenario(source_file).name;
    const fs::path judged_out = dir / "judged";
    const CliResult r = bouncecheck("run " + judged + " --engines reference --no-timings --trajectory ev=" +
                                    (out / name / "exact.csv").string() + " --out " + judged_out.string());
    EXPECT_TRUE(r.status == 0 || r.status == 1) << r.output;
    const auto report = nlohmann::json::parse(slurp(judged_out / "report.json"));
    for (const auto& sim : report["scenarios"][0]["simulators"])
        if (sim["simulator"] == "ev") return sim["comparison"]["damping"];
    ADD_FAILURE() << "no ev row";
    return {};
}

TEST(ImpactMeasureCli, EventDrivenSimulatorReadsTheLawAtEveryScale) {
    const fs::path dir = fresh_dir("scales");
    const std::string scenarios = BOUNCECHECK_SCENARIO_DIR;
    for (const char* name : {"seed-2d", "seed-3d", "earth-drop", "game-throw"}) {
        const std::string file = scenarios + "/" + name + ".toml";
        const Scenario s = load_scenario(file);
        const nlohmann::json d = event_driven_damping(dir / name, file, file);
        EXPECT_TRUE(d["reproduces"].get<bool>()) << name << " " << d.dump();
        EXPECT_GE(d["contacts"].get<int>(), 2) << name;
        EXPECT_NEAR(d["normal_worst"].get<double>(), s.alpha, 1e-6) << name;
        if (d["tangential_contacts"].get<int>() > 0) EXPECT_NEAR(d["tangential_worst"].get<double>(), s.beta, 1e-6);
    }
    fs::remove_all(dir);
}

TEST(ImpactMeasureCli, EventDrivenWithoutTheTangentialLossFails) {
    const fs::path dir = fresh_dir("beta");
    const std::string seed = std::string(BOUNCECHECK_SCENARIO_DIR) + "/seed-3d.toml";
    std::string text = slurp(seed);
    const std::string law = "tangential = 0.99";
    ASSERT_NE(text.find(law), std::string::npos);
    for (const char* beta : {"1.0", "0.97"}) {
        std::string variant = text;
        variant.replace(variant.find(law), law.size(), std::string("tangential = ") + beta);
        const fs::path file = dir / (std::string("beta-") + beta + ".toml");
        std::ofstream(file) << variant;
        const nlohmann::json d = event_driven_damping(dir / beta, file.string(), seed);
        EXPECT_FALSE(d["reproduces"].get<bool>()) << beta << " " << d.dump();
        EXPECT_NE(d["verdict"].get<std::string>().find("tangential loss"), std::string::npos) << d.dump();
        EXPECT_NEAR(d["normal_worst"].get<double>(), 0.8, 1e-6) << beta;  // its alpha reads exact
    }
    fs::remove_all(dir);
}

// An engine that holds the ball on the wall for a step (Havok does, measured:
// docs/engines.md): the sample after the crossing lies on the wall, stopped
// (`braked` 0) or still moving into it at `braked` times its speed, and the
// next one has left the wall with alpha times the speed the ball had at that
// sample's instant, beta on the other components at the stop. The impact
// must read alpha and beta as it does for an engine that bounces within the
// step (before, the stop read restitution 0, a braked arrival up to 9).
std::string held_bounces_csv(const Scenario& s, double braked) {
    const double g = -s.gravity[2], r = s.radius, dt = s.dt;
    std::string csv = "t,x,y,z,vx,vy,vz\n";
    Vec3 p = s.position, v = s.velocity;
    const auto row = [&](double t) {
        csv += fmt::format("{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g}\n", t, p.x(), p.y(), p.z(), v.x(),
                           v.y(), v.z());
    };
    row(0);
    double held_speed = 0;  // > 0: the ball is held on the floor, to leave at alpha times this
    DocumentClock clock(dt, s.duration);
    for (std::int64_t k = 1; k <= document_step_count(dt, s.duration); ++k) {
        clock.advance();
        p.x() += v.x() * dt;
        p.y() += v.y() * dt;
        if (held_speed > 0) {
            v.z() = s.alpha * held_speed;  // leaves the wall at the held sample's instant
            p.z() = r + v.z() * dt - 0.5 * g * dt * dt;
            v.z() -= g * dt;
            held_speed = 0;
        } else if (p.z() + v.z() * dt - 0.5 * g * dt * dt < r) {
            held_speed = -v.z() + g * dt;  // its free flight's speed at this instant
            p.z() = r;
            v.z() = -braked * held_speed;
            v.x() *= s.beta;
            v.y() *= s.beta;
        } else {
            p.z() += v.z() * dt - 0.5 * g * dt * dt;
            v.z() -= g * dt;
        }
        row(clock.t());
    }
    return csv;
}

TEST(ImpactMeasureCli, AnImpactHeldOnTheWallForAStepReadsTheLaw) {
    const fs::path dir = fresh_dir("held");
    // The seed's scale and Earth's: a ball thrown along x in a room long
    // enough that it meets only the floor.
    const struct {
        const char* name;
        double g, dt, speed, duration;
    } scales[] = {{"seed", 0.0981, 0.03, 0.01, 40.0}, {"earth", 9.81, 1.0 / 60, 0.3, 2.0}};
    for (const auto& scale : scales) {
        const fs::path file = dir / (std::string(scale.name) + ".toml");
        std::ofstream(file) << fmt::format(
            "name = \"{}\"\n[room]\nsize = [100.0, 1.0, 1.0]\n[ball]\nradius = 0.05\nposition = [0.5, 0.5, 0.9]\n"
            "velocity = [{}, 0.0, 0.0]\n[world]\ngravity = [0.0, 0.0, -{}]\n[damping]\nnormal = 0.8\ntangential = 0.99\n"
            "[run]\ndt = {:.17g}\nduration = {}\n",
            scale.name, scale.speed, scale.g, scale.dt, scale.duration);
        const Scenario s = load_scenario(file.string());
        for (const double braked : {0.0, 0.1}) {
            const std::string label = fmt::format("{} braked {}", scale.name, braked);
            const fs::path csv = dir / fmt::format("{}-{}.csv", scale.name, braked);
            std::ofstream(csv) << held_bounces_csv(s, braked);
            const fs::path out = dir / fmt::format("{}-{}-out", scale.name, braked);
            const CliResult r = bouncecheck("run " + file.string() + " --engines reference --no-timings --trajectory held=" +
                                            csv.string() + " --out " + out.string());
            ASSERT_TRUE(r.status == 0 || r.status == 1) << r.output;
            const auto report = nlohmann::json::parse(slurp(out / "report.json"));
            bool found = false;
            for (const auto& sim : report["scenarios"][0]["simulators"]) {
                if (sim["simulator"] != "held") continue;
                found = true;
                ASSERT_GE(sim["contacts_measured"].size(), 3u) << label;
                for (std::size_t i = 0; i < 3; ++i) {
                    const auto& e = sim["contacts_measured"][i];
                    EXPECT_NEAR(e["normal_coefficient"].get<double>(), 0.8, 1e-9) << label << " " << e;
                    EXPECT_NEAR(e["tangential_retention"].get<double>(), 0.99, 1e-9) << label << " " << e;
                }
            }
            EXPECT_TRUE(found) << label;
        }
    }
    fs::remove_all(dir);
}

// What the held-impact measure must leave alone (a review found both): a
// dead ball (alpha 0) stopped on the floor and then meeting a side wall a
// step later, and a ball thrown up against the ceiling, whose free flight
// slows by exactly a step of gravity each step. The reference reads the law
// at every contact (a corner's normal reads alpha beta: the law scales it
// for the other wall).
TEST(ImpactMeasureCli, TheHeldImpactMeasureLeavesTheReferenceExact) {
    const fs::path dir = fresh_dir("held-reference");
    const auto reference_events = [&](const std::string& file, const std::string& label) {
        const fs::path out = dir / label;
        const CliResult r = bouncecheck("run " + file + " --engines reference --no-timings --out " + out.string());
        EXPECT_TRUE(r.status == 0 || r.status == 1) << r.output;
        return nlohmann::json::parse(slurp(out / "report.json"))["scenarios"][0]["simulators"][0];
    };
    const nlohmann::json dead = reference_events(std::string(BOUNCECHECK_SCENARIO_DIR) + "/stress/dead-ball.toml", "dead");
    EXPECT_TRUE(dead["comparison"]["damping"]["reproduces"].get<bool>()) << dead["comparison"]["damping"];
    for (const auto& e : dead["contacts_measured"])
        if (!e["tangential_retention"].is_null()) EXPECT_NEAR(e["tangential_retention"].get<double>(), 0.99, 1e-9) << e;
    for (const double dt : {1e-3, 1.0 / 60}) {
        const fs::path file = dir / fmt::format("ceiling-{}.toml", dt);
        std::ofstream(file) << fmt::format(
            "name = \"ceiling\"\n[room]\nsize = [1.0, 1.0, 1.0]\n[ball]\nradius = 0.05\nposition = [0.5, 0.5, 0.2]\n"
            "velocity = [0.3, 0.2, 6.5]\n[world]\ngravity = [0.0, 0.0, -9.81]\n[damping]\nnormal = 0.8\n"
            "tangential = 0.99\n[run]\ndt = {:.17g}\nduration = 3.0\n",
            dt);
        const nlohmann::json ceiling = reference_events(file.string(), fmt::format("ceiling-{}", dt));
        int at_ceiling = 0;
        for (const auto& e : ceiling["contacts_measured"]) {
            const double t = e["t"].get<double>();
            int walls_then = 0;  // a corner: two walls in one step
            for (const auto& other : ceiling["contacts_measured"]) walls_then += other["t"].get<double>() == t;
            const double alpha = walls_then > 1 ? 0.8 * 0.99 : 0.8;
            EXPECT_NEAR(e["normal_coefficient"].get<double>(), alpha, 1e-9) << dt << " " << e;
            at_ceiling += e["axis"] == 2 && e["side"] == 1;
        }
        EXPECT_GE(at_ceiling, 2) << dt;
    }
    fs::remove_all(dir);
}

}  // namespace
}  // namespace bouncecheck
