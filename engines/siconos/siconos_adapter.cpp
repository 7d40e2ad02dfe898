// Siconos 4.4 adapters (see siconos_adapter.h): the scenario turned into a
// siconos_model::ModelSpec, the per-contact hook, and the settings report.
//
// How Siconos bounces the ball. Each wall is a LagrangianLinearTIR whose
// output y is the gap, with a NewtonImpactNSL(alpha): Newton's impact law
// y_dot+ = -alpha y_dot- holds by construction, no threshold, no softness.
// - siconos (TimeStepping, MoreauJeanOSI): at each step a wall is active if
//   the predicted gap y + h/2 y_dot is <= 0 (MoreauJeanOSI::addInteractionInIndexSet);
//   the LCP then gives y_dot+ + alpha y_dot >= 0 complementary to the
//   impulse, y_dot the velocity the step starts from; q+ = q + h ((1 -
//   theta) v + theta v+). No position correction: the ball goes as deep as a
//   step carries it and leaves from there.
// - siconos-ed (EventDriven, LsodarOSI): ODEPACK's DLSODAR integrates the
//   smooth motion and finds the roots of the gaps; at a root the impact LCP
//   applies the law, and a post-impact normal speed within _TOL_ED puts the
//   ball at rest on the wall (indexSet 2, an acceleration LCP holds it).
// beta is no Siconos law (NewtonImpactFrictionNSL is Coulomb): per-contact
// mode scales the tangential velocity here, once per contact.
#include "engines/siconos/siconos_adapter.h"

#include "engines/engine.h"
#include "engines/siconos/siconos_model.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <cmath>
#include <limits>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <dlfcn.h>

namespace bouncecheck {
namespace siconos {
namespace {

using siconos_model::Model;
using siconos_model::ModelSpec;
using siconos_model::Scheme;
using WallStatuses = siconos_model::Model::WallStatuses;

// Siconos's numerics call BLAS, and Debian's libblas.so.3 is OpenBLAS, which
// starts a thread per core and keeps it spinning (sched_yield) after each
// call. Measured on seed-2d (sweep, siconos alone, one job): 15-17 s of wall
// time but 33 s of CPU, half of it in the kernel; with one thread 19.4 s and
// 19.4 s, every result bit for bit the same. In a pool of worker processes
// that spinning thread takes the other workers' cores, so each process gets
// one BLAS thread. Returns the number OpenBLAS now uses; 0 when the BLAS is
// not OpenBLAS (nothing to set).
int limit_blas_threads() {
    static const int threads = [] {
        using Set = void (*)(int);
        using Get = int (*)();
        const auto set = reinterpret_cast<Set>(::dlsym(RTLD_DEFAULT, "openblas_set_num_threads"));
        const auto get = reinterpret_cast<Get>(::dlsym(RTLD_DEFAULT, "openblas_get_num_threads"));
        if (!set || !get) return 0;
        set(1);
        return get();
    }();
    return threads;
}


// Why two worlds must not step at once (checked in the 4.4.0 sources and in
// the libraries' exported data symbols).
constexpr const char* kTimeSteppingSerial =
    "Siconos 4.4 writes unsynchronised globals: every DynamicalSystem and Interaction constructor increments a "
    "static counter (DynamicalSystem::__count, Interaction::__count), every Event constructor sets the static "
    "Event::_eventCreated, and numerics' 3D one-contact friction solver keeps its function pointers in file statics "
    "(fc3d_onecontact_nonsmooth_Newton_solvers.c) written at every solve";
constexpr const char* kEventDrivenSerial =
    "LsodarOSI hands ODEPACK's DLSODAR its callbacks through one global pointer (global_object, set at every "
    "integrate), DLSODAR keeps its state in Fortran COMMON blocks, and EventDriven's event tolerance _TOL_ED is a "
    "static; plus the constructors' static counters of the time-stepping simulator";

// Siconos's own Zeno end takes about 130 impacts on the seeds.
constexpr std::int64_t kMaxEventsPerStep = 10000;

std::string num(double x) { return fmt::format("{:.17g}", x); }

// DLSODAR returns a root at the far end of its last bracket, up to HMING =
// 100 UROUND (|t| + |h|) after the crossing (opkda1.f, DRCHEK), so the gap
// there is down to -|v| HMING; EventDriven::updateIndexSet throws ("output of
// level 0 must be positive") below -_TOL_ED. |t| and Lsodar's step |h| are at
// most the final time, |v| at most max_ball_speed: _TOL_ED is raised to that
// bound where it exceeds Siconos's (a 950 m fall at 600 s, a 8400 s elastic
// run), and left as it is on the seeds (1.2e-12 m against 2.2e-12 m).
double event_tolerance(const Scenario& s, double final_time, const Tuning& t) {
    if (!t.size_event_tolerance) return t.event_tolerance;
    const double hming = 100 * std::numeric_limits<double>::epsilon() * 2 * final_time;
    return std::max(t.event_tolerance, max_ball_speed(s) * hming);
}

ModelSpec model_spec(const Scenario& s, const EngineOptions& options, const Tuning& t, bool event_driven) {
    ModelSpec m;
    m.scheme = event_driven ? Scheme::event_driven : Scheme::moreau_jean;
    m.dim = s.dim;
    const bool per_contact = options.tangential_model == TangentialModel::per_contact;
    m.friction = per_contact ? 0.0 : options.friction;
    // Rotation only matters through friction: without it the ball's spin is
    // uncoupled and left out.
    m.rotation = m.friction > 0 && options.free_rotation;
    m.mass = 1.0;
    m.radius = s.radius;
    for (int i = 0; i < 3; ++i) {
        m.position[i] = s.position[i];
        m.velocity[i] = s.velocity[i];
        m.gravity[i] = s.gravity[i];
    }
    for (const Wall& w : room_walls(s)) m.walls.push_back({w.axis, w.side, w.offset});
    m.restitution = s.alpha;
    m.dt = s.dt;
    // Beyond the last sample the document clock can reach (duration + dt),
    // so that the simulation always has a next event. s.dt is the engine step,
    // dt / substeps: the clock's step is substeps of them. (With 3 engine
    // steps, substeps = 128 stepped past T, and Siconos's next time came out
    // NaN: an assertion in TimeStepping aborted the whole process.)
    m.final_time = s.duration + 3 * s.dt * std::max(1, options.substeps);
    m.theta = t.theta;
    m.gamma = t.gamma;
    m.use_gamma_for_relation = t.use_gamma_for_relation;
    m.activation_threshold = t.activation_threshold;
    m.set_solver_options = t.set_solver_options;
    m.solver_tolerance = t.solver_tolerance;
    m.solver_max_iterations = t.solver_max_iterations;
    m.lsodar_rtol = t.lsodar_rtol;
    m.lsodar_atol = t.lsodar_atol;
    m.event_tolerance = event_driven ? event_tolerance(s, m.final_time, t) : t.event_tolerance;
    return m;
}

class SiconosWorld final : public World {
public:
    SiconosWorld(const Scenario& s, const EngineOptions& options, const Tuning& t, bool event_driven,
                 std::vector<Setting>& settings)
        : tuning_(t), event_driven_(event_driven), dim_(s.dim), dt_(s.dt), beta_(s.beta),
          per_contact_(options.tangential_model == TangentialModel::per_contact), walls_(room_walls(s)),
          gravity_(s.gravity), s_alpha_(s.alpha), model_(model_spec(s, options, t, event_driven)) {
        was_active_.assign(walls_.size(), false);
        report(s, options, settings);
    }

    void step() override {
        ++stats_.steps;
        if (event_driven_) step_event_driven();
        else step_time_stepping();
    }

    void read(State& out) const override {
        const auto p = model_.position();
        const auto v = model_.velocity();
        out.p = Vec3(p[0], p[1], dim_ == 3 ? p[2] : 0.0);
        out.v = Vec3(v[0], v[1], dim_ == 3 ? v[2] : 0.0);
    }

    const Stats& stats() const override { return stats_; }

private:
    // One time step: the nonsmooth problem solved, then (per-contact) beta
    // on a contact that started in it, then the step closed.
    void step_time_stepping() {
        const auto v_start = model_.velocity();
        model_.compute_step();
        if (per_contact_) {
            const WallStatuses walls = model_.walls();
            auto p = model_.position();
            auto v = model_.velocity();
            bool scaled = false;
            for (std::size_t w = 0; w < walls_.size(); ++w) {
                // A contact is a step whose LCP gave this wall an impulse; it
                // starts when the previous step gave none.
                const bool active = walls[w].impulse > 0;
                if (active && !was_active_[w]) {
                    ++stats_.new_contacts;
                    const Wall& wall = walls_[w];
                    if (moves_into_wall(v_start[wall.axis], gravity_[wall.axis], wall.side)) {
                        for (int a = 0; a < dim_; ++a) {
                            if (a == wall.axis) continue;
                            const double scaled_v = beta_ * v[a];
                            // q+ was q + h ((1 - theta) v + theta v+): redo it with the scaled v+.
                            if (tuning_.correct_position) p[a] += tuning_.theta * dt_ * (scaled_v - v[a]);
                            v[a] = scaled_v;
                        }
                        ++stats_.beta_applied;
                        scaled = true;
                    }
                }
                was_active_[w] = active;
            }
            if (scaled) model_.set_translation(p, v);
        }
        model_.finish_step();
    }

    // Every event up to the next sample time: Lsodar to the next root or
    // time-discretisation instant, then the event processed.
    void step_event_driven() {
        const double target = static_cast<double>(stats_.steps) * dt_;
        // A nonsmooth event within 1e-9 dt before the sample (1e-12 s at
        // dt 1e-3) ends the step there: the ball is then that close in time.
        std::int64_t events = 0;
        while (model_.current_time() < target - 1e-9 * dt_) {
            // A Zeno accumulation Siconos does not close (e.g. a ball pressed
            // into an edge by tilted gravity) would never reach the sample.
            if (++events > kMaxEventsPerStep)
                throw std::runtime_error(fmt::format(
                    "siconos-ed: more than {} events within one step at t = {:.17g} s: a Zeno accumulation that "
                    "Siconos's event tolerance does not close",
                    kMaxEventsPerStep, model_.current_time()));
            const bool root = model_.advance_to_event();
            if (tuning_.zeno_limit && root) close_accumulation();
            const auto v_pre = model_.velocity();
            const WallStatuses before = model_.walls();
            model_.process_events();
            // Impacts happen at roots, and at t = 0 when the ball starts
            // touching a wall (EventDriven schedules an event there). A
            // velocity written at a time-discretisation event would be lost
            // anyway: Lsodar continues from its own history there, and only
            // restarts from the state after a root.
            if (per_contact_ && (root || model_.current_time() == 0.0)) apply_beta_at_event(v_pre, before);
        }
        stats_.events = model_.counters().events;
        stats_.roots = model_.counters().roots;
    }

    // At a root, before Siconos processes it: an impact on a wall gravity
    // presses into, after which the law's Zeno accumulation has less than
    // zeno_close_time left (2 alpha u / (|g_n| (1 - alpha))), is the
    // accumulation's end: the velocity is set to its limit (normal 0, the
    // others beta^inf) and the outputs recomputed, so Siconos finds a
    // resting contact (indexSet 2) and holds the ball with its acceleration
    // LCP. Siconos alone closes only when a post-impact speed falls within
    // _TOL_ED, which its hops never reach under stronger gravity (g = 1 m/s^2,
    // alpha 0.5: they cycle at 2.2e-10 m/s, 7e-10 s apart, for good).
    void close_accumulation() {
        const WallStatuses walls = model_.walls();
        const auto p = model_.position();
        auto v = model_.velocity();
        bool closed = false;
        for (std::size_t w = 0; w < walls_.size(); ++w) {
            const Wall& wall = walls_[w];
            const double g_into = gravity_[wall.axis] * wall.side;
            const double u = v[wall.axis] * wall.side;  // > 0: into the wall
            if (walls[w].gap > model_.effective().event_tolerance || walls[w].in_resting_set || !(u > 0) || !(g_into > 0) ||
                !(s_alpha_ < 1))
                continue;
            const bool short_tail = 2 * s_alpha_ * u / (g_into * (1 - s_alpha_)) < tuning_.zeno_close_time;
            // The law's next hop, (alpha u)^2 / (2 g_n) high, lower than
            // Lsodar's error tolerance on the coordinate (rtol |q| + atol): it
            // is integrated with errors of its own size, the gap stays exactly
            // 0, and Siconos's hops stop shrinking, a root every few ns for
            // good (g = 8.8 m/s^2, alpha 0.92: at 1e-8 m/s).
            const siconos_model::Effective& e = model_.effective();
            const double resolution = e.lsodar_rtol * std::abs(p[wall.axis]) + e.lsodar_atol;
            const bool below_resolution = tuning_.zeno_close_below_resolution &&
                                          (s_alpha_ * u) * (s_alpha_ * u) / (2 * g_into) < resolution;
            if (!short_tail && !below_resolution) continue;
            // Friction mode (mu = 0 here: siconos-ed has no Coulomb friction)
            // keeps the tangential velocity; per-contact takes beta^inf.
            if (per_contact_) {
                for (int a = 0; a < dim_; ++a)
                    if (a != wall.axis && beta_ < 1) v[a] = 0.0;
                ++stats_.new_contacts;
                ++stats_.beta_applied;
            }
            v[wall.axis] = 0.0;
            ++stats_.zeno_closures;
            closed = true;
        }
        if (closed) model_.set_translation(model_.position(), v, true);
    }

    // An impact is a wall the ball touches after the event that it was moving
    // into before it (strictly: a ball at rest against a wall from the start
    // makes no impact, Siconos keeps it in persistent contact, as exact does).
    void apply_beta_at_event(const std::array<double, 3>& v_pre, const WallStatuses& before) {
        const WallStatuses after = model_.walls();
        const auto p = model_.position();
        auto v = model_.velocity();
        bool scaled = false;
        for (std::size_t w = 0; w < walls_.size(); ++w) {
            const Wall& wall = walls_[w];
            if (after[w].gap > model_.effective().event_tolerance || before[w].in_resting_set) continue;
            if (v_pre[wall.axis] * wall.side <= 0) continue;
            ++stats_.new_contacts;
            ++stats_.beta_applied;
            // The contact closed (Siconos: the post-impact speed is within
            // _TOL_ED): the law's remaining contacts (infinitely many,
            // accumulating at this instant) leave beta^inf.
            const bool closed = after[w].in_resting_set && tuning_.zeno_limit;
            if (closed) ++stats_.zeno_closures;
            for (int a = 0; a < dim_; ++a)
                if (a != wall.axis) v[a] = closed && beta_ < 1 ? 0.0 : beta_ * v[a];
            if (closed) v[wall.axis] = 0.0;
            scaled = true;
        }
        if (scaled) model_.set_translation(p, v);
    }

    void report(const Scenario& s, const EngineOptions& options, std::vector<Setting>& out) const;

    Tuning tuning_;
    bool event_driven_;
    int dim_;
    double dt_;
    double beta_;
    bool per_contact_;
    std::vector<Wall> walls_;
    Vec3 gravity_;
    double s_alpha_;
    Model model_;
    std::vector<bool> was_active_;
    Stats stats_;
};

void SiconosWorld::report(const Scenario& s, const EngineOptions& options, std::vector<Setting>& out) const {
    auto set = [&out](std::string key, std::string value, std::string why) {
        out.push_back({std::move(key), std::move(value), std::move(why)});
    };
    const siconos_model::Effective& e = model_.effective();
    const Tuning& t = tuning_;
    const bool friction = !per_contact_ && options.friction > 0;
    set("engine", fmt::format("{}, {}", e.version, event_driven_ ? "EventDriven + LsodarOSI" : "TimeStepping + MoreauJeanOSI"),
        "Debian libsiconos-kernel-dev / libsiconos-numerics-dev, linked directly; the Siconos headers are compiled "
        "in their own C++17 file (they do not compile as C++20)");
    set("precision", "double", "Siconos's SiconosVector and numerics are double throughout");
    set("unit_scale", "length 1, time 1 (SI)",
        "the tolerances below are absolute, and far below the seed's scale (5 cm ball, |g| dt down to 1e-4 m/s)");
    set("model",
        fmt::format("LagrangianLinearTIDS, {} DOF (translation{}), mass 1, external force m g = ({}, {}, {})", e.dofs,
                    e.dofs > s.dim ? " + rotation, inertia 2/5 m r^2" : " only", num(s.gravity.x()),
                    num(s.gravity.y()), num(s.gravity.z())),
        e.dofs > s.dim ? "rotation takes part in Coulomb friction through the contact point's slip"
                       : "without friction the ball's spin is uncoupled from its centre: left out");
    set("walls",
        fmt::format("{} LagrangianLinearTIR, y = gap (ball surface to the plane at 0 or size){}", walls_.size(),
                    friction ? ", then the contact point's slip along the wall's other axes" : ""),
        "planes, exact gap; no margin");
    set("impact_law",
        friction ? fmt::format("NewtonImpactFrictionNSL(e = {}, et = 0, mu = {})", num(s.alpha), num(options.friction))
                 : fmt::format("NewtonImpactNSL(e = {})", num(s.alpha)),
        "Newton's law y_dot+ = -e y_dot- holds by construction: no restitution threshold, no softness");
    if (!event_driven_) {
        set("dt_engine", fmt::format("{} s (TimeDiscretisation h)", num(dt_)),
            "one computeOneStep + nextStep per engine step (see substeps)");
        set("theta", num(e.theta),
            "MoreauJeanOSI(theta): q+ = q + h ((1 - theta) v + theta v+). Siconos's default, kept: free flight is "
            "then exact for constant gravity (the trapezoidal rule on a linear v)");
        set("gamma",
            e.use_gamma ? num(e.gamma) : fmt::format("not used (prediction y + {} h y_dot, Siconos's default)", num(e.gamma)),
            "the activation prediction of a wall for the step");
        set("activation_threshold", num(e.activation_threshold),
            "Siconos's default: a wall is active for the step when y + h/2 y_dot <= 0 (MoreauJeanOSI::addInteractionInIndexSet)");
        set("use_gamma_for_relation", e.use_gamma_for_relation ? "true" : "false", "Siconos's default");
        set("nonsmooth_problem", friction ? fmt::format("FrictionContact (dimension {})", s.dim) : "LCP",
            friction ? "Coulomb friction: NSGS with the one-contact solver" : "frictionless: an LCP over the active walls");
    } else {
        set("dt_engine", fmt::format("{} s (TimeDiscretisation h: output instants only)", num(dt_)),
            "Lsodar chooses its own steps; the run is sampled at every h, and events in between are processed");
        set("lsodar_tolerances", fmt::format("rtol {}, atol {} (itol 1)", num(e.lsodar_rtol), num(e.lsodar_atol)),
            "written into the arrays Lsodar reads (LsodarOSI::setTol with scalars writes rtol into atol). rtol is "
            "Siconos's 10 eps; atol 1e-16 instead of its 100 eps = 2.2e-14: the Zeno tail's hops lower than about "
            "1e-13 m were integrated with errors of their own size and ended early (seed-3d's ball rested 8.0e-7 m "
            "short of exact's). Free flight is a parabola, which Lsodar's Adams methods of order >= 2 integrate "
            "exactly");
        set("event_tolerance", fmt::format("{} m (EventDriven::_TOL_ED)", num(e.event_tolerance)),
            "Siconos's default 1000 x 10 eps, raised to max_ball_speed x 100 eps x 2 T where that is larger (Lsodar "
            "returns a root up to 100 eps (|t| + |h|) past the crossing; a deeper gap makes EventDriven throw), set by "
            "every world (it is a static). A gap within it is a contact; a post-impact normal speed within it closes "
            "the contact (Siconos's Zeno end: the ball rests on the wall)");
        set("event_time_grid", fmt::format("tick {} s, events within {} ticks merged", num(e.tick), e.gap_limit_ticks),
            "Siconos's defaults (Event::_tick, EventsManager::_GapLimit2Events): event times are integers of ticks");
        set("zeno_end",
            t.zeno_limit
                ? fmt::format("at a root on a wall gravity presses into, when the law's accumulation left after the "
                              "impact, 2 alpha u / (|g_n| (1 - alpha)), is below {} s: normal velocity 0 (and, "
                              "per-contact, the others beta^inf), outputs recomputed, Siconos then holds the ball "
                              "(indexSet 2); also when the law's next hop, (alpha u)^2 / (2 |g_n|), is lower than "
                              "Lsodar's error tolerance on the coordinate (rtol |q| + atol){}",
                              num(t.zeno_close_time), t.zeno_close_below_resolution ? "" : " [off]")
                : std::string("Siconos's own only (a post-impact speed within _TOL_ED)"),
            "Siconos's hops stop shrinking before _TOL_ED under stronger gravity (g = 1 m/s^2, alpha 0.5: they cycle "
            "at 2.2e-10 m/s, 7e-10 s apart, for good), and below Lsodar's resolution (g = 8.8 m/s^2, alpha 0.92: at "
            "1e-8 m/s, the gap exactly 0, more than 10000 roots in one step); the ball misses at most |v| x the time "
            "left of travel");
        set("nonsmooth_problem", "impact LCP (velocity level) and acceleration LCP, Lemke",
            "EventDriven's two problems; friction is refused (LsodarOSI does not implement NewtonImpactFrictionNSL)");
    }
    set("solver",
        fmt::format("{} (numerics id {}), tolerance {}, at most {} iterations", e.solver, e.solver_id,
                    num(e.solver_tolerance), e.solver_max_iterations),
        t.set_solver_options
            ? "set: numerics' defaults are 1e-6 / 10000 for Lemke (a pivoting method: the same run bit for bit, the "
              "tolerance only checks it) and 1e-4 / 1000 for friction NSGS (one contact converges in one sweep: a "
              "sliding bounce measured the same mu to 1e-13; the tolerance would matter at a corner's two or three "
              "coupled contacts)"
            : "numerics' defaults for this solver");
    set("solver_failure", event_driven_ ? "prints a warning (EventDriven has no check hook)" : "throws (TimeStepping::setCheckSolverFunction)",
        "Siconos's default prints two lines to stdout and goes on with what the solver left");
    set("projection", "none (no position-level correction)",
        event_driven_ ? "contacts are found at their exact instants: no penetration to correct"
                      : "TimeStepping, not TimeSteppingDirectProjection: the ball sinks at most one step of travel and "
                        "leaves from there");
    set("ccd", event_driven_ ? "not needed (roots of the gap functions)" : "none",
        event_driven_ ? "Lsodar locates every gap's zero crossing"
                      : "a step's travel is found as the predicted gap; substeps shorten it");
    if (per_contact_) {
        set("tangential_model", "per-contact",
            event_driven_
                ? fmt::format("after each event: every wall the ball touches and was moving into before it (an impact) "
                              "scales the other velocity components by beta = {}; an impact that closes the contact "
                              "(Siconos puts the ball at rest) {}",
                              num(beta_),
                              t.zeno_limit ? fmt::format("(or leaves less than {} s of the law's Zeno accumulation, "
                                                         "2 u / (|g_n| (1 - alpha))) sets the velocity to the law's "
                                                         "limit: the other components beta^inf (0 for beta < 1) and the "
                                                         "normal 0 (Siconos leaves up to _TOL_ED m/s)",
                                                         num(t.zeno_close_time))
                                           : std::string("leaves the velocity as Siconos has it (zeno_limit off)"))
                : fmt::format("after the step's LCP: a wall with an impulse that had none at the previous step starts "
                              "a contact; if the ball moved into it at the start of the step (moves_into_wall), the "
                              "other velocity components are scaled by beta = {}{}",
                              num(beta_),
                              t.correct_position ? " and the step's position update is redone with them (theta h of the change)"
                                                 : " after the step (its position update unscaled)"));
    } else {
        set("tangential_model", "friction", fmt::format("Coulomb mu = {} (the scenario's [engines.{}] friction)",
                                                        num(options.friction),
                                                        (event_driven_ ? kEventDrivenIdentity : kTimeSteppingIdentity).name));
    }
    set("rotation", e.dofs > s.dim ? "free" : (options.free_rotation ? "not modelled (no friction)" : "locked"),
        "scenario [engines.<name>] rotation");
    set("threads", event_driven_ ? kEventDrivenSerial : kTimeSteppingSerial,
        "one world at a time per process: run, sweep and stress give each run a worker process of its own");
    const int blas = limit_blas_threads();
    set("blas_threads", blas > 0 ? std::to_string(blas) : "not OpenBLAS: its own",
        "OpenBLAS's default is one thread per core, spinning between calls: it took a second core per process "
        "and gave the same results");
}

// cannot_run() also refuses Coulomb friction for siconos-ed: LsodarOSI throws
// for a NewtonImpactFrictionNSL (LsodarOSI::initializeWorkVectorsForInteraction,
// 4.4.0: "not yet implemented").
class SiconosSimulator final : public EngineSimulator {
public:
    SiconosSimulator(const Tuning& t, bool event_driven) : tuning_(t), event_driven_(event_driven) {
        limit_blas_threads();  // once the module is loaded, before any world of this process
    }
    std::string_view name() const override { return identity().name; }
    std::string_view description() const override { return identity().description; }
    double typical_ns_per_step() const override { return identity().typical_ns_per_step; }
    EngineCapabilities capabilities() const override {
        EngineCapabilities caps;
        caps.precision = "double";
        return caps;
    }
    std::optional<std::string> cannot_run(const Scenario& s) const override {
        if (auto why = EngineSimulator::cannot_run(s)) return why;
        const EngineOptions o = s.engine_options(std::string(name()));
        if (event_driven_ && o.tangential_model == TangentialModel::friction && o.friction > 0)
            return fmt::format("siconos-ed cannot run Coulomb friction (mu = {}): Siconos 4.4's LsodarOSI does not "
                               "implement NewtonImpactFrictionNSL; use tangential_model = \"per-contact\", mu = 0, "
                               "or the time-stepping simulator \"siconos\"",
                               o.friction);
        if (event_driven_ && o.tangential_model == TangentialModel::per_contact && s.alpha == 1 && s.beta < 1) {
            int pressed = 0;
            for (int a = 0; a < s.dim; ++a) pressed += s.gravity[a] != 0;
            if (pressed >= 2)
                return fmt::format(
                    "siconos-ed cannot run alpha = 1 with per-contact beta = {} under gravity along {} axes: the "
                    "ball is driven into an edge or corner, where the law's bounces accumulate (each wall's beta "
                    "damps the other's normal speed); EventDriven closes an accumulation only when a post-impact "
                    "normal speed falls within _TOL_ED, which alpha = 1 never does, and the adapter's closures need "
                    "alpha < 1, so the run ends in more than 10000 events within one step",
                    s.beta, pressed);
        }
        return std::nullopt;
    }

protected:
    std::unique_ptr<EngineWorld> build(const Scenario& s, const EngineOptions& options,
                                       std::vector<Setting>& settings) const override {
        return build_world(s, options, tuning_, event_driven_, settings);
    }

private:
    const EngineIdentity& identity() const { return event_driven_ ? kEventDrivenIdentity : kTimeSteppingIdentity; }

    Tuning tuning_;
    bool event_driven_;
};

}  // namespace

std::unique_ptr<World> build_world(const Scenario& s, const EngineOptions& options, const Tuning& tuning,
                                   bool event_driven, std::vector<Setting>& settings) {
    return std::make_unique<SiconosWorld>(s, options, tuning, event_driven, settings);
}

std::unique_ptr<const Simulator> make_time_stepping_simulator(const Tuning& tuning) {
    return std::make_unique<SiconosSimulator>(tuning, false);
}

std::unique_ptr<const Simulator> make_event_driven_simulator(const Tuning& tuning) {
    return std::make_unique<SiconosSimulator>(tuning, true);
}

}  // namespace siconos

std::unique_ptr<const Simulator> make_siconos_simulator() { return siconos::make_time_stepping_simulator({}); }
std::unique_ptr<const Simulator> make_siconos_event_driven_simulator() {
    return siconos::make_event_driven_simulator({});
}

}  // namespace bouncecheck

// The entries the registry looks up when it loads this adapters' module
// (registry/engine_module.h).
extern "C" const bouncecheck::Simulator* bouncecheck_engine_siconos() {
    return bouncecheck::make_siconos_simulator().release();
}
extern "C" const bouncecheck::Simulator* bouncecheck_engine_siconos_ed() {
    return bouncecheck::make_siconos_event_driven_simulator().release();
}
