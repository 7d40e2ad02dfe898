// MuJoCo 2.2.2 adapter: the ball is a sphere geom on slide joints (x, y, z in
// 3D; x and z in 2D) plus a rotational joint when rotation is free, the room
// six planes (four in 2D) on the world body. The model is written as MJCF
// text and compiled by mj_loadXML from an in-memory file; one mj_step of dt
// is one engine step.
//
// How MuJoCo makes a contact (engine_collision_driver.c, engine_core_constraint.c,
// engine_forward.c of 2.2): at the start of mj_step, mj_collision finds every
// ball-wall pair closer than the margin (a plane is a half-space: however deep
// the ball is, a contact is made); each contact becomes a constraint row whose
// reference acceleration is aref = -b v - k x (solref; v the normal velocity,
// x the signed distance), reached through the impedance d (solimp): the
// solver gives a = a_free + d' (aref - a_free) while that pushes (never pulls),
// then Euler: v += a dt, x += v dt. There is no restitution coefficient.
//
// Axes. 3D: scenario (x, y, z) = MuJoCo (x, y, z), gravity along -z. 2D: the
// scenario's (x, y) = MuJoCo (x, z): the ball has no y joint, so it stays in
// the y = 0 plane by construction, and MuJoCo's vertical is z in both cases.
// Units: SI (UnitScale 1); the contact law has no length or speed threshold.
#include "engines/mujoco/mujoco_adapter.h"

#include <fmt/format.h>
#include <mujoco/mujoco.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <memory>
#include <mutex>
#include <numbers>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#ifndef BOUNCECHECK_MUJOCO_VERSION
#define BOUNCECHECK_MUJOCO_VERSION "unknown"
#endif

static_assert(sizeof(mjtNum) == 8, "MuJoCo must be built with mjtNum = double");
static_assert(mjVERSION_HEADER == 222, "the adapter's settings were measured on MuJoCo 2.2.2");

namespace bouncecheck {
namespace mujoco {
namespace {

constexpr double kPi = std::numbers::pi;

std::string num(double x) { return fmt::format("{:.17g}", x); }

// --------------------------------------------------------------- library state

// The warning text of the world stepping on this thread (see step()).
thread_local std::string* tls_warning = nullptr;

// MuJoCo's process-wide handlers (engine_util_errmem.c). By default
// mju_warning appends to MUJOCO_LOG.TXT in the working directory and prints to
// stdout, and mju_error does the same, then waits for Enter on stdin and
// exit(1)s. Installed once (the pointers are plain globals: written here
// only, under std::call_once): a warning goes to the world stepping on the
// calling thread, an error becomes a C++ exception (the Debian library is C
// built with unwind tables, as gcc does by default on x86-64; the world that
// threw is destroyed, never stepped again). The model compiler installs its
// own thread-local handlers while it runs (user_model.cc), which take
// precedence, and reports through mj_loadXML's error buffer.
void on_warning(const char* msg) {
    if (tls_warning && tls_warning->empty()) *tls_warning = msg;
}
[[noreturn]] void on_error(const char* msg) { throw std::runtime_error(std::string("MuJoCo error: ") + msg); }

// Points on_warning at a world's text for the duration of its MuJoCo calls,
// and away again however they end.
struct WarningScope {
    explicit WarningScope(std::string* text) { tls_warning = text; }
    ~WarningScope() { tls_warning = nullptr; }
    WarningScope(const WarningScope&) = delete;
    WarningScope& operator=(const WarningScope&) = delete;
};

void ensure_library() {
    static std::once_flag once;
    std::call_once(once, [] {
        if (mj_version() != mjVERSION_HEADER)
            throw std::runtime_error(fmt::format("libmujoco is version {}, the headers {}", mj_version(),
                                                 mjVERSION_HEADER));
        mju_user_warning = &on_warning;
        mju_user_error = &on_error;
    });
}

// mj_loadXML parses and compiles under the library's own lock: xml_api.cc
// keeps the last parsed model in a global (`themodel`, for mj_saveLastXML)
// behind a static std::mutex; the compiler's error handlers are thread-local
// (user_model.cc) and the engine keeps no other mutable global (the mjcb_*
// callbacks and mju_user_* handlers are only read while stepping). So worlds
// may step on several threads at once. This lock makes the compile's
// serialisation the adapter's own rather than a property of the library build.
std::mutex& load_mutex() {
    static std::mutex m;
    return m;
}

struct ModelDeleter {
    void operator()(mjModel* m) const { mj_deleteModel(m); }
};
struct DataDeleter {
    void operator()(mjData* d) const { mj_deleteData(d); }
};

std::unique_ptr<mjModel, ModelDeleter> compile(const std::string& xml) {
    auto vfs = std::make_unique<mjVFS>();
    mj_defaultVFS(vfs.get());
    const char* name = "bouncecheck.xml";
    if (mj_makeEmptyFileVFS(vfs.get(), name, static_cast<int>(xml.size())) != 0)
        throw std::runtime_error("MuJoCo: cannot make the in-memory model file");
    std::memcpy(vfs->filedata[mj_findFileVFS(vfs.get(), name)], xml.data(), xml.size());
    char error[1000] = "";
    mjModel* m = nullptr;
    {
        const std::lock_guard<std::mutex> lock(load_mutex());
        m = mj_loadXML(name, vfs.get(), error, sizeof(error));
    }
    mj_deleteVFS(vfs.get());
    if (!m) throw std::runtime_error(std::string("MuJoCo cannot compile the model: ") + error);
    std::unique_ptr<mjModel, ModelDeleter> out(m);
    // A warning from the compiler means the model is not what was written.
    if (error[0]) throw std::runtime_error(std::string("MuJoCo compiler warning: ") + error);
    return out;
}

// ------------------------------------------------------------- contact law

// Scenario axis -> MuJoCo axis: 2D (x, y) runs in MuJoCo's x-z plane.
int engine_axis(int dim, int axis) { return dim == 3 ? axis : (axis == 0 ? 0 : 2); }

// The flat impedance MuJoCo uses for one contact (getimpedance: dmin = dmax,
// or a zero width, give their mean), or dmax when it varies with depth.
double impedance(const Tuning& t) {
    const double lo = std::clamp(t.solimp[0], mjMINIMP, mjMAXIMP);
    const double hi = std::clamp(t.solimp[1], mjMINIMP, mjMAXIMP);
    return lo == hi || t.solimp[2] <= mjMINVAL ? 0.5 * (lo + hi) : hi;
}

}  // namespace

SpringRestitution spring_restitution(double omega_dt, double damping_dt) {
    // Time in steps (dt = 1), incoming speed 1: the map is linear in the speed.
    const double k = omega_dt * omega_dt, b = damping_dt;
    auto bounce = [&](double phase, int* steps) {
        double x = -phase, v = -1;  // the first state found inside the wall
        int n = 0;
        for (; x < 0 && n < 100000; ++n) {
            const double a = std::max(0.0, -b * v - k * x);
            v += a;
            x += v;
        }
        if (steps) *steps = n;
        return v;
    };
    SpringRestitution r;
    r.lowest = 1e300;
    r.highest = -1e300;
    constexpr int kPhases = 64;
    for (int i = 0; i < kPhases; ++i) {
        const double e = bounce((i + 0.5) / kPhases, nullptr);
        r.mean += e / kPhases;
        r.lowest = std::min(r.lowest, e);
        r.highest = std::max(r.highest, e);
    }
    bounce(0.5, &r.steps);
    return r;
}

ContactParameters contact_parameters(const Scenario& s, const Tuning& t) {
    ContactParameters c;
    c.v_max = max_ball_speed(s);
    const double d = impedance(t);
    const double inverse_mass_ratio = s.dim == 3 ? 1.0 : 2.0 / 3.0;  // A~ / A, see the header
    c.impedance_factor = t.correct_for_impedance ? 1 / (d + (1 - d) * inverse_mass_ratio) : 1.0;

    if (t.law == ContactLaw::one_step_damper) {
        // The step that finds the ball at depth phi u dt (phi in [0, 1)) gives
        // v' = -v (1 - b' dt) + k' phi u dt^2 (b', k' as the ball feels them):
        // with k' dt^2 = anchor and b' dt = 1 + alpha - anchor / 2 the
        // outgoing speed is (alpha + anchor (phi - 1/2)) u, alpha on average.
        // See Tuning::damper_anchor.
        const double anchor = t.damper_anchor * (1 - s.alpha);
        c.omega_dt = std::sqrt(anchor);
        c.stiffness = anchor / (s.dt * s.dt) / c.impedance_factor;
        c.damping_derived = (1 + s.alpha) / s.dt;
        c.damping = (1 + s.alpha - anchor / 2) / s.dt / c.impedance_factor;
        c.rule = fmt::format("one-step damper with an anchor spring: k dt^2 = {} (1 - alpha) = {}",
                             num(t.damper_anchor), num(anchor));
        return c;
    }
    if (t.law == ContactLaw::engine_default) {
        c.rule = "MuJoCo's default solref (0.02, 1)";
        return c;
    }
    // Spring: omega from the stiffness rule, zeta from alpha (linear oscillator:
    // alpha = exp(-pi zeta / sqrt(1 - zeta^2))), then b corrected so that the
    // replayed step gives alpha on average over the crossing phase.
    double omega = 0;
    if (t.spring_stiffness > 0) {
        omega = std::sqrt(t.spring_stiffness);
        c.rule = fmt::format("fixed k = {}", num(t.spring_stiffness));
    } else {
        const double by_steps = kPi / (t.spring_steps * s.dt);
        const double by_depth = c.v_max / (t.spring_penetration * s.radius);
        const double cap = kPi / (t.spring_min_steps * s.dt);
        omega = std::min(std::max(by_steps, by_depth), cap);
        c.rule = omega == cap        ? fmt::format("capped: the contact lasts {} steps", num(t.spring_min_steps))
                 : by_depth > by_steps ? fmt::format("depth: v_max / ({} r)", num(t.spring_penetration))
                                       : fmt::format("steps: the contact lasts {} steps", num(t.spring_steps));
    }
    c.stiffness = omega * omega;
    c.omega_dt = omega * s.dt;
    const double ln = std::log(std::max(s.alpha, 1e-12));
    const double zeta = s.alpha >= 1 ? 0.0 : -ln / std::sqrt(kPi * kPi + ln * ln);
    c.damping_derived = 2 * zeta * omega;
    double b_dt = c.damping_derived * s.dt;
    if (t.spring_correct_damping && s.alpha < 1) {
        // The replayed restitution falls as b grows: bisect b dt.
        double lo = 0, hi = std::max(4 * b_dt, 1e-3);
        while (spring_restitution(c.omega_dt, hi).mean > s.alpha && hi < 1e3) hi *= 2;
        for (int i = 0; i < 60; ++i) {
            const double mid = 0.5 * (lo + hi);
            (spring_restitution(c.omega_dt, mid).mean > s.alpha ? lo : hi) = mid;
        }
        b_dt = 0.5 * (lo + hi);
    }
    c.stiffness /= c.impedance_factor;
    c.damping = b_dt / s.dt / c.impedance_factor;
    return c;
}

namespace {

class MujocoWorld final : public World {
public:
    MujocoWorld(const Scenario& s, const EngineOptions& options, const Tuning& tuning,
                std::vector<Setting>& settings)
        : tuning_(tuning),
          dim_(s.dim),
          beta_(s.beta),
          per_contact_(options.tangential_model == TangentialModel::per_contact) {
        ensure_library();
        const ContactParameters contact = contact_parameters(s, tuning);
        mu_ = per_contact_ ? 0.0 : options.friction;
        condim_ = tuning.condim > 0 ? tuning.condim : (mu_ > 0 ? 3 : 1);
        const double wall_mu = tuning.wall_friction < 0 ? mu_ : tuning.wall_friction;
        free_rotation_ = options.free_rotation;
        xml_ = model_xml(s, tuning, contact, wall_mu);
        model_ = compile(xml_);
        data_.reset(mj_makeData(model_.get()));
        if (!data_) throw std::runtime_error("MuJoCo: mj_makeData failed");
        mjModel* m = model_.get();
        mjData* d = data_.get();

        ball_geom_ = mj_name2id(m, mjOBJ_GEOM, "ball");
        for (const Wall& w : room_walls(s)) {
            const int id = mj_name2id(m, mjOBJ_GEOM, fmt::format("wall{}", walls_.size()).c_str());
            if (id < 0 || id >= kMaxWalls) throw std::runtime_error("MuJoCo: wall geom missing");
            walls_.push_back({id, engine_axis(dim_, w.axis), w.side});
        }
        for (int a = 0; a < 3; ++a) {
            const int j = mj_name2id(m, mjOBJ_JOINT, fmt::format("slide{}", a).c_str());
            qpos_[a] = j < 0 ? -1 : m->jnt_qposadr[j];
            dof_[a] = j < 0 ? -1 : m->jnt_dofadr[j];
        }
        for (int i = 0; i < dim_; ++i) {
            const int a = engine_axis(dim_, i);
            d->qpos[qpos_[a]] = s.position[i];
            d->qvel[dof_[a]] = s.velocity[i];
        }
        report(s, options, contact, wall_mu, settings);
    }

    void step() override {
        std::string warning;
        {
            const WarningScope scope(&warning);
            advance();
        }
        ++stats_.steps;
        stats_.max_contacts = std::max(stats_.max_contacts, data_->ncon);
        if (tuning_.fail_on_warning) check(warning);
    }

    void read(State& out) const override {
        const mjData* d = data_.get();
        // Every step: SI units (UnitScale 1), scenario axis i is MuJoCo axis
        // engine_axis(dim, i), read straight from the slide joints.
        out.p = Vec3::Zero();
        out.v = Vec3::Zero();
        for (int i = 0; i < dim_; ++i) {
            const int a = engine_axis(dim_, i);
            out.p[i] = d->qpos[qpos_[a]];
            out.v[i] = d->qvel[dof_[a]];
        }
    }

    Vec3 engine_position() const override {
        Vec3 p = Vec3::Zero();
        for (int a = 0; a < 3; ++a)
            if (qpos_[a] >= 0) p[a] = data_->qpos[qpos_[a]];
        return p;
    }
    Vec3 engine_velocity() const override {
        Vec3 v = Vec3::Zero();
        for (int a = 0; a < 3; ++a)
            if (dof_[a] >= 0) v[a] = data_->qvel[dof_[a]];
        return v;
    }
    Vec3 engine_gravity() const override {
        return {model_->opt.gravity[0], model_->opt.gravity[1], model_->opt.gravity[2]};
    }
    double engine_timestep() const override { return model_->opt.timestep; }
    double ball_mass() const override { return model_->body_mass[model_->geom_bodyid[ball_geom_]]; }
    int rotational_dofs() const override { return model_->nv - dim_; }
    const Stats& stats() const override { return stats_; }
    const std::string& model_xml() const override { return xml_; }

private:
    static constexpr int kMaxWalls = 6;
    struct EngineWall {
        int geom;
        int axis;  // MuJoCo axis of the wall's normal
        int side;  // -1 lower wall, +1 upper
    };

    // One mj_step of opt.timestep, with the per-contact hook where it applies.
    void advance() {
        mjModel* m = model_.get();
        mjData* d = data_.get();
        if (per_contact_ && tuning_.beta_in_split_step) {
            // mj_step1: positions (collision, constraint rows) and velocities
            // (efc_vel, aref); the hook scales qvel; mj_step2: forces, the
            // constraint solve and the Euler update from the scaled velocity.
            mj_step1(m, d);
            if (apply_beta(d->qvel)) mj_fwdVelocity(m, d);  // velocity-dependent terms of the scaled qvel
            mj_step2(m, d);
        } else if (per_contact_) {
            // After mj_step, d->contact still holds the contacts this step
            // found, but the velocity has been solved: the law's condition
            // is judged on the velocity the step started from.
            mjtNum before[3] = {0, 0, 0};
            for (int a = 0; a < 3; ++a)
                if (dof_[a] >= 0) before[a] = d->qvel[dof_[a]];
            mj_step(m, d);
            apply_beta(before);
        } else {
            mj_step(m, d);
        }
    }

    // The MJCF for the scenario: every setting that matters written out.
    std::string model_xml(const Scenario& s, const Tuning& t, const ContactParameters& c, double wall_mu) const {
        Vec3 g = Vec3::Zero();
        for (int i = 0; i < dim_; ++i) g[engine_axis(dim_, i)] = s.gravity[i];
        std::string option;
        if (t.set_timestep) option += fmt::format(" timestep=\"{}\"", num(s.dt));
        if (t.set_gravity) option += fmt::format(" gravity=\"{} {} {}\"", num(g[0]), num(g[1]), num(g[2]));
        option += fmt::format(" integrator=\"{}\"", t.integrator == Integrator::euler ? "Euler"
                                                      : t.integrator == Integrator::rk4 ? "RK4"
                                                                                         : "implicit");
        option += fmt::format(" cone=\"{}\" impratio=\"{}\"", t.cone == Cone::elliptic ? "elliptic" : "pyramidal",
                              num(t.impratio));
        option += " solver=\"Newton\" iterations=\"100\" tolerance=\"1e-8\" noslip_iterations=\"0\"";
        option += " density=\"0\" viscosity=\"0\" wind=\"0 0 0\"";
        const std::string solref = t.law == ContactLaw::engine_default
                                       ? "0.02 1"
                                       : fmt::format("{} {}", num(-c.stiffness), num(-c.damping));
        const std::string solimp = fmt::format("{} {} {} {} {}", num(t.solimp[0]), num(t.solimp[1]),
                                               num(t.solimp[2]), num(t.solimp[3]), num(t.solimp[4]));
        std::string xml = fmt::format(
            "<mujoco model=\"bouncecheck\">\n"
            "  <compiler angle=\"radian\" inertiafromgeom=\"true\"/>\n"
            "  <size nconmax=\"8\" njmax=\"48\"/>\n"
            "  <option{}/>\n"
            "  <default>\n"
            "    <geom condim=\"{}\" friction=\"{} 0 0\" solref=\"{}\" solimp=\"{}\" margin=\"{}\" gap=\"{}\""
            " solmix=\"1\" priority=\"0\" contype=\"1\" conaffinity=\"1\"/>\n"
            "    <joint damping=\"0\" armature=\"0\" frictionloss=\"0\" stiffness=\"0\"/>\n"
            "  </default>\n"
            "  <worldbody>\n",
            option, condim_, num(mu_), solref, solimp, num(t.margin), num(t.gap));
        int n = 0;
        for (const Wall& w : room_walls(s)) {
            Vec3 p = Vec3::Zero(), normal = Vec3::Zero();
            const int a = engine_axis(dim_, w.axis);
            p[a] = w.offset;
            normal[a] = -w.side;  // into the room
            xml += fmt::format(
                "    <geom name=\"wall{}\" type=\"plane\" size=\"0 0 1\" pos=\"{} {} {}\" zaxis=\"{} {} {}\""
                " friction=\"{} 0 0\"/>\n",
                n++, num(p[0]), num(p[1]), num(p[2]), num(normal[0]), num(normal[1]), num(normal[2]), num(wall_mu));
        }
        xml += "    <body name=\"ball\" pos=\"0 0 0\">\n";
        for (int a = 0; a < 3; ++a) {
            if (dim_ == 2 && a == 1) continue;
            xml += fmt::format("      <joint name=\"slide{}\" type=\"slide\" axis=\"{} {} {}\"/>\n", a, a == 0 ? 1 : 0,
                               a == 1 ? 1 : 0, a == 2 ? 1 : 0);
        }
        if (free_rotation_)
            xml += dim_ == 3 ? "      <joint name=\"spin\" type=\"ball\"/>\n"
                             : "      <joint name=\"spin\" type=\"hinge\" axis=\"0 1 0\"/>\n";
        xml += fmt::format("      <geom name=\"ball\" type=\"sphere\" size=\"{}\"{}/>\n", num(s.radius),
                           t.ball_mass > 0 ? fmt::format(" mass=\"{}\"", num(t.ball_mass)) : std::string());
        xml += "    </body>\n  </worldbody>\n</mujoco>\n";
        return xml;
    }

    // Per-contact beta: every ball-wall contact in d->contact (found by this
    // step's mj_collision at the step's starting position, inside the
    // margin and not excluded by the gap) that was not there at the previous
    // step starts a contact; if the law counts it, every velocity component of
    // the ball but that wall's normal is scaled by beta, once. Returns
    // whether qvel changed. `judged`: the velocity the law's condition reads
    // (qvel itself in the split step; indexed by dof there, by axis otherwise).
    bool apply_beta(const mjtNum* judged) {
        const mjData* d = data_.get();
        unsigned now = 0;
        for (int i = 0; i < d->ncon; ++i) {
            const mjContact& c = d->contact[i];
            if (c.exclude) continue;
            const int other = c.geom1 == ball_geom_ ? c.geom2 : c.geom2 == ball_geom_ ? c.geom1 : -1;
            for (std::size_t w = 0; w < walls_.size(); ++w)
                if (walls_[w].geom == other) now |= 1u << w;
        }
        bool scaled = false;
        for (std::size_t w = 0; w < walls_.size(); ++w) {
            if (!((now >> w) & 1u) || ((touching_ >> w) & 1u)) continue;
            ++stats_.new_wall_contacts;
            const EngineWall& wall = walls_[w];
            mjtNum* qvel = data_->qvel;
            const mjtNum vn = judged == qvel ? qvel[dof_[wall.axis]] : judged[wall.axis];
            if (!moves_into_wall(vn, model_->opt.gravity[wall.axis], wall.side)) continue;
            for (int a = 0; a < 3; ++a)
                if (a != wall.axis && dof_[a] >= 0) qvel[dof_[a]] *= beta_;
            ++stats_.beta_applied;
            scaled = true;
        }
        if (now) ++stats_.touching_steps;
        touching_ = now;
        return scaled;
    }

    void check(const std::string& warning) const {
        const mjData* d = data_.get();
        static constexpr const char* kNames[mjNWARNING] = {"INERTIA", "CONTACTFULL", "CNSTRFULL", "VGEOMFULL",
                                                           "BADQPOS", "BADQVEL",     "BADQACC",   "BADCTRL"};
        for (int i = 0; i < mjNWARNING; ++i)
            if (d->warning[i].number > 0)
                throw std::runtime_error(fmt::format(
                    "MuJoCo warning mjWARN_{} at t = {:.6g}{}{}", kNames[i], d->time,
                    i >= mjWARN_BADQPOS && i <= mjWARN_BADQACC ? " (MuJoCo reset the ball to its start)" : "",
                    warning.empty() ? "" : ": " + warning));
        if (!warning.empty()) throw std::runtime_error("MuJoCo warning: " + warning);
    }

    void report(const Scenario& s, const EngineOptions& options, const ContactParameters& c, double wall_mu,
                std::vector<Setting>& out) const;

    Tuning tuning_;
    int dim_;
    double beta_;
    bool per_contact_;
    double mu_ = 0;
    int condim_ = 1;
    bool free_rotation_ = true;
    std::string xml_;
    std::unique_ptr<mjModel, ModelDeleter> model_;
    std::unique_ptr<mjData, DataDeleter> data_;
    int ball_geom_ = -1;
    std::vector<EngineWall> walls_;
    int qpos_[3] = {-1, -1, -1};
    int dof_[3] = {-1, -1, -1};
    unsigned touching_ = 0;  // bit per wall index, at the previous step's collision
    Stats stats_;
};

void MujocoWorld::report(const Scenario& s, const EngineOptions& options, const ContactParameters& c,
                         double wall_mu, std::vector<Setting>& out) const {
    auto set = [&out](std::string key, std::string value, std::string why) {
        out.push_back({std::move(key), std::move(value), std::move(why)});
    };
    const Tuning& t = tuning_;
    const mjModel* m = model_.get();
    set("engine", fmt::format("MuJoCo {} (mj_versionString() = {}, mjVERSION_HEADER {})", BOUNCECHECK_MUJOCO_VERSION,
                              mj_versionString(), mjVERSION_HEADER),
        "Debian libmujoco-dev; the model is MJCF text compiled by mj_loadXML from an in-memory file "
        "(report: model_xml in the tests)");
    set("precision", "double (mjtNum)", "sizeof(mjtNum) == 8 checked at compile time");
    set("unit_scale", "length 1, time 1 (SI)",
        "the contact law below has no length or speed threshold (margin 0, gap 0, no restitution threshold)");
    set("timestep", t.set_timestep ? fmt::format("{} s (opt.timestep = dt)", num(m->opt.timestep))
                                   : fmt::format("{} s (MuJoCo default)", num(m->opt.timestep)),
        "one mj_step per engine step, and mj_step advances opt.timestep: MuJoCo's 0.002 s would run the scene "
        "at 0.002 / dt of its speed (1/15 at dt 0.03)");
    set("integrator",
        t.integrator == Integrator::euler ? "Euler (semi-implicit: v += a dt, then x += v dt)"
        : t.integrator == Integrator::rk4 ? "RK4"
                                          : "implicit",
        "MuJoCo's default. The contact law is written for one Euler update per step; RK4 re-runs collision and "
        "the damper at its stages: measured, the ball never turns and stops 0.1 mm inside the floor. Per-contact "
        "mode splits the step (mj_step1 / mj_step2), which integrates with Euler in any case");
    set("gravity",
        t.set_gravity ? fmt::format("({}, {}, {}) m/s^2 (MuJoCo frame)", num(m->opt.gravity[0]),
                                    num(m->opt.gravity[1]), num(m->opt.gravity[2]))
                      : "MuJoCo default (0, 0, -9.81)",
        "the scenario's; MuJoCo's default is Earth's, 100x the seeds'");
    set("axes", dim_ == 3 ? "scenario (x, y, z) = MuJoCo (x, y, z)" : "scenario (x, y) = MuJoCo (x, z); no y joint",
        dim_ == 3 ? "MuJoCo is 3D, z up" : "the ball has slide joints on x and z only: it cannot leave y = 0");

    // --- contact law
    const char* law = t.law == ContactLaw::one_step_damper ? "one-step damper"
                      : t.law == ContactLaw::spring        ? "spring"
                                                           : "MuJoCo default";
    if (t.law == ContactLaw::engine_default) {
        set("contact.law", "MuJoCo default: solref (0.02, 1) (time constant 0.02 s, damping ratio 1)",
            "critically damped: no bounce to speak of. Measured at dt 1e-3: second apex 0.059 m instead of 0.459 "
            "(seed-3d), 0.062 instead of 0.619 (seed-2d); the ball is dead at 6.7 s and 5.5 s");
    } else {
        set("contact.law",
            fmt::format("{}: solref (direct) = ({}, {}), i.e. stiffness k = {} 1/s^2, damping b = {} 1/s per unit "
                        "mass",
                        law, num(-c.stiffness), num(-c.damping), num(c.stiffness), num(c.damping)),
            t.law == ContactLaw::one_step_damper
                ? "MuJoCo has no restitution: a contact row's reference acceleration is aref = -b v - k x. With "
                  "b dt = 1 + alpha the step that finds the ball inside a wall turns its normal velocity from -u to "
                  "alpha u at any depth; the row then goes inactive (it would pull) and the ball leaves. Measured: "
                  "alpha within 1e-5 (the anchor) at every depth, from the velocity the step starts with (as Bullet "
                  "and ODE). A spring lasting N steps gives a restitution that depends on where within a step the "
                  "ball crosses the wall (0.786 to 0.829 at N = 10, replayed), its sampled reversal falls "
                  "mid-contact, and at dt 1e-3 with N ~ 11 it moved seed-2d's third apex by 6.6%"
                : "a spring-damper lasting several steps (ContactLaw::spring)");
        set("contact.stiffness_rule", fmt::format("{} (k = {}, sqrt(k) dt = {}, v_max = {} m/s)", c.rule,
                                                  num(c.stiffness), num(c.omega_dt), num(c.v_max)),
            t.law == ContactLaw::one_step_damper
                ? "k dt^2 = damper_anchor (1 - alpha): the contact lasts one step (two when the ball was found deeper than "
                  "alpha u dt), the ball sinks at most one step of travel (|v| dt), and a penetration turns into at "
                  "most k dt x depth of speed. The anchor holds a resting ball against the 1e-4 of gravity the "
                  "impedance leaks: without it the ball sinks 1.6e-7 m/s at dt 0.03 (1.6 cm over long-horizon-3d's "
                  "1e5 s); with it, it rests g dt^2 / (1 - alpha) deep (0.44 mm at dt 0.03, 4.9 um at dt 1e-3). "
                  "It moves each bounce's restitution by up to k dt^2 / 2: scaled by 1 - alpha because nothing "
                  "damps that at alpha = 1 (a constant 1e-4 drifted stress/elastic's energy 0.0108 J/kg against "
                  "its 0.0072 tolerance)"
                : "stiffer than the step can resolve is unstable (sqrt(k) dt < 2) and phase-dependent; softer sinks "
                  "the ball deeper and delays each bounce by the contact's duration");
        set("contact.damping",
            fmt::format("derived b = {} 1/s, used b = {} 1/s", num(c.damping_derived), num(c.damping)),
            t.law == ContactLaw::one_step_damper
                ? fmt::format("derived: (1 + alpha) / dt for an ideal constraint; used: (1 + alpha - k dt^2 / 2) "
                              "/ dt (the anchor's mean kick) divided by the impedance factor {} (d = {}, {})",
                              num(c.impedance_factor), num(impedance(t)),
                              dim_ == 3 ? "3D: the factor is 1" : "2D: MuJoCo's inverse-mass estimate is 2/3 of "
                                                                  "the ball's, one axis being locked")
                : fmt::format("derived: 2 zeta omega with alpha = exp(-pi zeta / sqrt(1 - zeta^2)); used: "
                              "corrected so that the replayed step (semi-implicit Euler, a contact never pulls) "
                              "gives alpha on average over the crossing phase, divided by the impedance factor {}",
                              num(c.impedance_factor)));
    }
    set("contact.solimp", fmt::format("({}, {}, {}, {}, {})", num(t.solimp[0]), num(t.solimp[1]), num(t.solimp[2]),
                                      num(t.solimp[3]), num(t.solimp[4])),
        "flat impedance d = dmin = dmax = 0.9999 (mjMAXIMP): the row reaches 99.99% of aref, 1e-4 of gravity leaks "
        "into a contact step, and the law does not change with depth. MuJoCo's default (0.9, 0.95, 0.001, 0.5, 2) "
        "reaches 90-95% of aref depending on depth and lets 5-10% of gravity through: measured restitution 0.74 at "
        "dt 1e-3, seed-2d's second apex 0.532 m instead of 0.619, rest 10 s early");
    set("contact.margin_gap", fmt::format("margin {}, gap {}", num(t.margin), num(t.gap)),
        "MuJoCo's defaults: a contact row exists from distance < margin - gap; with a margin the law acts on the "
        "ball before it reaches the wall");
    set("contact.condim", std::to_string(condim_),
        condim_ == 1 ? "frictionless (per-contact mode, or mu = 0): MuJoCo's default 3 would add friction rows with "
                       "the walls' default friction 1 (a contact takes the larger geom's)"
                     : "normal and two sliding directions (Coulomb); torsional and rolling friction off (condim 4, 6)");
    set("contact.friction",
        fmt::format("ball {} 0 0, walls {} 0 0 (a contact takes the larger of the two, clamped to mjMINMU 1e-5)",
                    num(mu_), num(wall_mu)),
        per_contact_ ? "per-contact mode: mu = 0, beta applied by the step hook"
                     : "the scenario's [engines.mujoco] friction on both, so the larger is mu; MuJoCo's default "
                       "1 0.005 0.0001 on the walls would make every contact's mu 1");
    set("contact.cone", t.cone == Cone::elliptic ? "elliptic" : "pyramidal",
        "elliptic is Coulomb's cone; MuJoCo's default pyramid (four edges) bounds the friction along a diagonal "
        "slip at mu N / sqrt(2): measured 0.0354 for mu 0.05 (friction mode only)");
    set("contact.impratio", num(t.impratio),
        "MuJoCo's default; it scales the friction rows' regulariser only (measured: 8e-8 m/s on a sliding bounce at "
        "10). The friction rows share the normal's aref = -b v: a sticking contact reverses its slip by -alpha, "
        "and a sliding one adds mu (v_t,out + alpha v_t,in) to the normal speed (the elliptic cone's middle "
        "zone); impratio changes neither (friction mode only)");
    set("contact.override", "off (mjENBL_OVERRIDE clear: opt.o_margin, o_solref, o_solimp unused)", "MuJoCo default");
    set("solver", "Newton, 100 iterations, tolerance 1e-8, noslip 0, warm start on",
        "MuJoCo's defaults; one ball and at most three contacts converge in a step or two");
    set("walls", fmt::format("{} planes on the world body at x_i = 0 and x_i = size_i, normals inward", walls_.size()),
        "sphere-plane distance is exact and a plane is a half-space: a ball however deep still gets a contact");
    set("ball", fmt::format("sphere r = {} m, {} (inertia 2/5 m r^2, from the geom)", num(s.radius),
                            t.ball_mass > 0 ? fmt::format("mass {} kg", num(m->body_mass[1]))
                                            : fmt::format("MuJoCo's density 1000: {} kg", num(m->body_mass[1]))),
        "the contact law is per unit mass (solref direct: accelerations) and friction is mu N: mass-free");
    set("joints",
        fmt::format("slides on {}{}; damping 0, armature 0, frictionloss 0, stiffness 0, unlimited",
                    dim_ == 3 ? "x, y, z" : "x, z",
                    free_rotation_ ? (dim_ == 3 ? " + ball joint" : " + hinge about y") : " (rotation locked)"),
        "MuJoCo's defaults, written out: any of them would drag the ball");
    set("rotation", free_rotation_ ? "free" : "locked (no rotational joint)", "scenario [engines.mujoco] rotation");
    set("fluid", "density 0, viscosity 0, wind 0", "MuJoCo's defaults: no drag");
    set("sleeping", "none", "MuJoCo 2.2 has no sleeping or deactivation");
    set("ccd", "none",
        "MuJoCo has no continuous collision detection; a step's travel is found as overlap with the half-space "
        "planes, and substeps shorten the travel");
    set("sizes", fmt::format("nconmax {}, njmax {}, nstack {}", m->nconmax, m->njmax, m->nstack),
        "one ball touches at most three walls; MuJoCo's 100 contacts and 500 rows cost a 10 MB stack per world");
    set("warnings",
        t.fail_on_warning ? "a MuJoCo warning fails the run (mju_user_warning and mju_user_error installed once)"
                          : "ignored",
        "mj_step silently resets the ball to its start on a NaN or a value beyond 1e10 (a warning only); "
        "MuJoCo's default handlers also write MUJOCO_LOG.TXT into the working directory and print to stdout, "
        "and its error handler waits for Enter then exits");
    set("threads", "worlds step concurrently; compiles are serialised (mj_loadXML's global model, behind a mutex)",
        "MuJoCo 2.2 keeps its state in mjModel / mjData; xml_api.cc's global last model is locked");
    set("tangential_model",
        per_contact_
            ? fmt::format("per-contact: beta = {} on the ball's qvel {}", num(beta_),
                          t.beta_in_split_step
                              ? "between mj_step1 and mj_step2 of the step whose collision first finds the contact "
                                "(then mj_fwdVelocity again): the velocity the constraint solve and the Euler update "
                                "start from"
                              : "after mj_step (the law judged on the velocity the step started from): one step after the contact was found")
            : fmt::format("friction: Coulomb mu = {}", num(mu_)),
        per_contact_ ? "every slide-joint velocity but the wall's normal, once when a contact starts (a ball-wall "
                       "contact in d->contact, not excluded, absent at the previous step) and the ball moves into "
                       "the wall (moves_into_wall)"
                     : "the scenario's [engines.mujoco] table");
    (void)options;
}

}  // namespace

std::unique_ptr<World> build_world(const Scenario& s, const EngineOptions& options, const Tuning& tuning,
                                   std::vector<Setting>& settings) {
    return std::make_unique<MujocoWorld>(s, options, tuning, settings);
}

std::unique_ptr<const Simulator> make_simulator(const Tuning& tuning) {
    EngineCapabilities caps;
    caps.planar_2d_in_3d = true;
    caps.precision = "double";
    return make_engine_simulator(
        {kIdentity, caps, [tuning](const Scenario& s, const EngineOptions& options, std::vector<Setting>& settings)
             -> std::unique_ptr<EngineWorld> { return build_world(s, options, tuning, settings); }});
}

}  // namespace mujoco

std::unique_ptr<const Simulator> make_mujoco_simulator() { return mujoco::make_simulator(mujoco::Tuning::chosen()); }

}  // namespace bouncecheck

// The entry the registry looks up when it loads this adapter's module
// (registry/engine_module.h).
extern "C" const bouncecheck::Simulator* bouncecheck_engine_mujoco() {
    return bouncecheck::make_mujoco_simulator().release();
}
