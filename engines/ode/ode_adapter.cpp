// ODE 0.16 adapter: the ball is a sphere geom on a dynamic body, the room six
// static planes (four in 2D), contacts come from dSpaceCollide's near callback
// as contact joints, and one dWorldStep of dt is one scenario step.
//
// Axes. 3D: scenario (x, y, z) = ODE (x, y, z), gravity along -z.
// 2D: ODE's planar joint (dJointCreatePlane2D) keeps a body in ODE's x-y plane
// (z = 0, rotation about z only), so the scenario's (x, y) = ODE (x, y) with
// gravity along ODE's -y; ODE's z is the locked out-of-plane axis.
//
// Units: SI, no scaling (UnitScale 1): with bounce_vel, surface layer, contact
// ERP and max correcting velocity all 0, no length or speed threshold is left
// in ODE's contact path, and dWorldStep's LCP is exact in double precision, so
// a 5 cm ball behaves like a 5 m one.
#include "engines/ode/ode_adapter.h"

#include <fmt/format.h>
#include <ode/ode.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>

#ifndef BOUNCECHECK_ODE_VERSION
#define BOUNCECHECK_ODE_VERSION "unknown"
#endif

static_assert(sizeof(dReal) == 8, "ODE must be built in double precision (dDOUBLE)");

namespace bouncecheck {
namespace ode {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

// ODE keeps global state (collision tables, per-thread caches): dInitODE2
// exactly once per process (a function-local static, thread-safe in C++11),
// dCloseODE at exit, and per-thread data allocated for every thread that
// builds a world (dAllocateODEDataForThread is idempotent per thread).
void ensure_ode_initialised() {
    struct Library {
        Library() {
            if (!dInitODE2(0)) throw std::runtime_error("dInitODE2 failed");
            if (!dCheckConfiguration("ODE_double_precision"))
                throw std::runtime_error("libode is not built in double precision");
        }
        ~Library() { dCloseODE(); }
        Library(const Library&) = delete;
        Library& operator=(const Library&) = delete;
    };
    static const Library library;
    if (!dAllocateODEDataForThread(dAllocateMaskAll)) throw std::runtime_error("dAllocateODEDataForThread failed");
}

std::string num(double v) {
    if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
    return fmt::format("{}", v);
}

class OdeWorld final : public World {
public:
    OdeWorld(const Scenario& s, const EngineOptions& options, const Tuning& tuning,
             std::vector<Setting>& settings)
        : dim_(s.dim), alpha_(s.alpha), beta_(s.beta), h_(scale_.to_engine_time(s.dt)), options_(options),
          tuning_(tuning) {
        ensure_ode_initialised();
        mu_ = options.tangential_model == TangentialModel::per_contact ? 0.0
                                                                         : tuning.mu_override.value_or(options.friction);

        world_ = dWorldCreate();
        space_ = dSimpleSpaceCreate(nullptr);
        contacts_ = dJointGroupCreate(0);

        // Gravity: scenario axis i is ODE axis i in both 2D and 3D.
        dWorldSetGravity(world_, scale_.to_engine_acceleration(s.gravity[0]),
                         scale_.to_engine_acceleration(s.gravity[1]),
                         s.dim == 3 ? scale_.to_engine_acceleration(s.gravity[2]) : 0.0);
        dWorldSetERP(world_, tuning.world_erp);
        dWorldSetCFM(world_, tuning.world_cfm);
        dWorldSetContactSurfaceLayer(world_, tuning.surface_layer);
        dWorldSetContactMaxCorrectingVel(world_, tuning.max_correcting_vel);
        dWorldSetAutoDisableFlag(world_, tuning.auto_disable ? 1 : 0);
        dWorldSetLinearDamping(world_, 0);
        dWorldSetAngularDamping(world_, 0);
        dWorldSetMaxAngularSpeed(world_, dInfinity);
        dWorldSetQuickStepNumIterations(world_, tuning.quick_step_iterations);

        // The ball.
        body_ = dBodyCreate(world_);
        dMass mass;
        dMassSetSphereTotal(&mass, tuning.ball_mass, scale_.to_engine_length(s.radius));
        dBodySetMass(body_, &mass);
        dBodySetAutoDisableFlag(body_, tuning.auto_disable ? 1 : 0);
        dBodySetPosition(body_, scale_.to_engine_length(s.position[0]), scale_.to_engine_length(s.position[1]),
                         s.dim == 3 ? scale_.to_engine_length(s.position[2]) : 0.0);
        dBodySetLinearVel(body_, scale_.to_engine_velocity(s.velocity[0]), scale_.to_engine_velocity(s.velocity[1]),
                          s.dim == 3 ? scale_.to_engine_velocity(s.velocity[2]) : 0.0);
        dBodySetAngularVel(body_, 0, 0, 0);
        ball_ = dCreateSphere(space_, scale_.to_engine_length(s.radius));
        dGeomSetBody(ball_, body_);
        // ODE returns the body's own arrays, valid until the system's
        // structure changes (it never does once built): taken once here
        // rather than by two library calls per step.
        position_ = dBodyGetPosition(body_);
        velocity_ = dBodyGetLinearVel(body_);

        // The walls: static planes n.p = d with n pointing into the room.
        for (const Wall& w : room_walls(s)) {
            double n[3] = {0, 0, 0};
            n[w.axis] = -w.side;
            const double d = -w.side * scale_.to_engine_length(w.offset);
            const dGeomID g = dCreatePlane(space_, n[0], n[1], n[2], d);
            dGeomSetData(g, reinterpret_cast<void*>(static_cast<std::intptr_t>(walls_.size())));
            walls_.push_back(w);
        }

        if (s.dim == 2) {
            // Planar joint: z velocity and x/y angular velocities held at 0.
            plane_ = dJointCreatePlane2D(world_, nullptr);
            dJointAttach(plane_, body_, nullptr);
            if (!options.free_rotation) {
                dJointSetPlane2DAngleParam(plane_, dParamVel, 0);
                dJointSetPlane2DAngleParam(plane_, dParamFMax, dInfinity);
            }
        } else if (!options.free_rotation) {
            // Angular motor on the three world axes at zero speed, unbounded torque.
            lock_ = dJointCreateAMotor(world_, nullptr);
            dJointAttach(lock_, body_, nullptr);
            dJointSetAMotorMode(lock_, dAMotorUser);
            dJointSetAMotorNumAxes(lock_, 3);
            dJointSetAMotorAxis(lock_, 0, 0, 1, 0, 0);
            dJointSetAMotorAxis(lock_, 1, 0, 0, 1, 0);
            dJointSetAMotorAxis(lock_, 2, 0, 0, 0, 1);
            for (int p : {dParamVel, dParamVel2, dParamVel3}) dJointSetAMotorParam(lock_, p, 0);
            for (int p : {dParamFMax, dParamFMax2, dParamFMax3}) dJointSetAMotorParam(lock_, p, dInfinity);
        }

        report(s, settings);
    }

    ~OdeWorld() override {
        dJointGroupDestroy(contacts_);
        dSpaceDestroy(space_);  // destroys the geoms it holds (cleanup mode on by default)
        dWorldDestroy(world_);  // destroys the body and the non-group joints
    }
    OdeWorld(const OdeWorld&) = delete;
    OdeWorld& operator=(const OdeWorld&) = delete;

    void step() override {
        touching_now_ = 0;
        dSpaceCollide(space_, this, &OdeWorld::near_callback);
        touching_before_ = touching_now_;
        const int ok = tuning_.stepper == Stepper::world_step ? dWorldStep(world_, h_) : dWorldQuickStep(world_, h_);
        dJointGroupEmpty(contacts_);
        if (!ok) throw std::runtime_error("ODE step failed (out of memory)");
    }

    // Every step: ODE runs in SI units (no scaling) and scenario axis i is
    // ODE axis i; z is 0 in 2D (the planar joint's plane).
    void read(State& out) const override {
        static_assert(scale_.length == 1.0 && scale_.time == 1.0);
        out.p = Vec3(position_[0], position_[1], dim_ == 3 ? position_[2] : 0.0);
        out.v = Vec3(velocity_[0], velocity_[1], dim_ == 3 ? velocity_[2] : 0.0);
    }

    Vec3 engine_position() const override {
        const dReal* p = dBodyGetPosition(body_);
        return {p[0], p[1], p[2]};
    }
    Vec3 engine_angular_velocity() const override {
        const dReal* w = dBodyGetAngularVel(body_);
        return {w[0], w[1], w[2]};
    }
    const Stats& stats() const override { return stats_; }

private:
    static void near_callback(void* data, dGeomID o1, dGeomID o2) {
        static_cast<OdeWorld*>(data)->collide(o1, o2);
    }

    void collide(dGeomID o1, dGeomID o2) {
        if (o1 != ball_ && o2 != ball_) return;  // wall-wall pairs: both static
        const dGeomID wall_geom = o1 == ball_ ? o2 : o1;
        const int wall = static_cast<int>(reinterpret_cast<std::intptr_t>(dGeomGetData(wall_geom)));
        const Wall& w = walls_[static_cast<std::size_t>(wall)];

        dContactGeom found[8];
        const int count = dCollide(o1, o2, std::min(tuning_.max_contacts, 8), found, sizeof(dContactGeom));
        if (count <= 0) return;
        ++stats_.pairs_touching;
        stats_.max_contacts_per_pair = std::max(stats_.max_contacts_per_pair, count);
        const unsigned bit = 1u << wall;
        touching_now_ |= bit;

        if (options_.tangential_model == TangentialModel::per_contact && !(touching_before_ & bit)) {
            // A contact starts: scale every velocity component but the wall's
            // normal by beta, once, if the law counts it (moves_into_wall).
            ++stats_.new_contacts;
            const dReal* v = dBodyGetLinearVel(body_);
            dVector3 gravity;
            dWorldGetGravity(world_, gravity);
            if (moves_into_wall(v[w.axis], gravity[w.axis], w.side)) {
                double nv[3] = {v[0], v[1], v[2]};
                for (int i = 0; i < dim_; ++i)
                    if (i != w.axis) nv[i] *= beta_;
                dBodySetLinearVel(body_, nv[0], nv[1], nv[2]);
            }
        }

        for (int i = 0; i < count; ++i) {
            dContact c{};  // value-initialised: no field left as garbage
            c.geom = found[i];
            c.surface.mode = dContactBounce;
            c.surface.bounce = alpha_;
            c.surface.bounce_vel = tuning_.bounce_vel;
            if (tuning_.contact_soft_erp) {
                c.surface.mode |= dContactSoftERP;
                c.surface.soft_erp = tuning_.contact_erp;
            }
            if (tuning_.contact_soft_cfm) {
                c.surface.mode |= dContactSoftCFM;
                c.surface.soft_cfm = tuning_.contact_cfm;
            }
            c.surface.mu = mu_;
            if (mu_ > 0) {
                if (tuning_.approx1) c.surface.mode |= dContactApprox1;
                set_friction_directions(c, w);
            }
            const dJointID j = dJointCreateContact(world_, contacts_, &c);
            dJointAttach(j, dGeomGetBody(o1), dGeomGetBody(o2));
            ++stats_.contact_joints;
        }
    }

    // ODE's friction is a pyramid: two rows, each bounded by mu N. With the
    // first row along the slip of the contact point, sliding friction is
    // mu N against the slip (the Coulomb cone), not up to sqrt(2) mu N along a
    // diagonal of two arbitrary axes. In 2D only the in-plane tangent has a row
    // (the out-of-plane one would duplicate the planar joint's z row).
    void set_friction_directions(dContact& c, const Wall& w) const {
        if (dim_ == 2) {
            c.surface.mode |= dContactMu2 | dContactFDir1;
            c.surface.mu2 = 0;
            c.fdir1[0] = c.fdir1[1] = c.fdir1[2] = 0;
            c.fdir1[1 - w.axis] = 1;
            return;
        }
        if (!tuning_.align_friction) return;
        const dReal* pc = c.geom.pos;
        const dReal* n = c.geom.normal;
        dVector3 slip;
        dBodyGetPointVel(body_, pc[0], pc[1], pc[2], slip);
        const double vn = slip[0] * n[0] + slip[1] * n[1] + slip[2] * n[2];
        double t[3] = {slip[0] - vn * n[0], slip[1] - vn * n[1], slip[2] - vn * n[2]};
        const double len = std::sqrt(t[0] * t[0] + t[1] * t[1] + t[2] * t[2]);
        if (!(len > 0)) return;  // no slip: any pair of axes holds it
        c.surface.mode |= dContactMu2 | dContactFDir1;
        c.surface.mu2 = mu_;
        for (int i = 0; i < 3; ++i) c.fdir1[i] = t[i] / len;
    }

    void report(const Scenario& s, std::vector<Setting>& out) const {
        auto add = [&out](std::string key, std::string value, std::string why) {
            out.push_back({std::move(key), std::move(value), std::move(why)});
        };
        const bool per_contact = options_.tangential_model == TangentialModel::per_contact;
        add("engine", fmt::format("ODE {} ({})", BOUNCECHECK_ODE_VERSION, dGetConfiguration()),
            "libode-dev from the distribution, linked through pkg-config");
        add("precision", "double", "sizeof(dReal) == 8 checked at compile time, dCheckConfiguration(ODE_double_precision) at run time");
        add("init", "dInitODE2(0) once per process (function-local static), dCloseODE at exit, dAllocateODEDataForThread per world",
            "ODE's global state must be initialised once; repeated runs and several worlds share it");
        add("scale", "1 (SI units, dt as given)",
            "no length or speed threshold left in ODE's contact path (bounce_vel, surface layer, contact ERP, max "
            "correcting velocity all 0), so scaling changes nothing");
        add("stepper", tuning_.stepper == Stepper::world_step ? "dWorldStep" : fmt::format("dWorldQuickStep ({} iterations)", tuning_.quick_step_iterations),
            "exact Dantzig LCP: measured restitution alpha to round-off; QuickStep's 20 SOR iterations give 0.79999999994. "
            "One body: the exact solve costs ~1 us per step");
        add("dt_engine", num(h_), "one dWorldStep of this per engine step (see substeps)");
        add("ccd", "none", "ODE has no continuous collision detection: a step's travel beyond the radius is found "
                           "as overlap with the half-space planes; substeps shorten the travel");
        add("axes", s.dim == 3 ? "scenario (x, y, z) = ODE (x, y, z)" : "scenario (x, y) = ODE (x, y); ODE z locked by dJointCreatePlane2D",
            s.dim == 3 ? "ODE is 3D" : "ODE's planar joint keeps a body in its x-y plane (z = 0, rotation about z only), so the vertical is ODE's y");
        add("collision", fmt::format("dSimpleSpace, sphere geom vs {} static planes, dSpaceCollide near callback, dCollide up to {} points per pair", walls_.size(), tuning_.max_contacts),
            "sphere-plane gives exactly one contact point per wall; a corner gives one per wall");
        add("restitution", fmt::format("surface.bounce = {} (dContactBounce), set per contact, no combine rule", num(alpha_)),
            "the contact joint targets outgoing normal speed = bounce x incoming speed");
        add("bounce_vel", num(tuning_.bounce_vel),
            "minimum incoming speed for a bounce: 0 keeps the ball bouncing until physics stops it (the samples' 0.1 m/s "
            "stops seed-2d on the floor after 8 bounces, t ~ 31 s, where exact bounces until 38 s)");
        add("contact_softness",
            fmt::format("soft_cfm {} ({}), soft_erp {} ({})", tuning_.contact_soft_cfm ? num(tuning_.contact_cfm) : num(tuning_.world_cfm),
                        tuning_.contact_soft_cfm ? "dContactSoftCFM" : "world", tuning_.contact_soft_erp ? num(tuning_.contact_erp) : num(tuning_.world_erp),
                        tuning_.contact_soft_erp ? "dContactSoftERP" : "world"),
            "CFM 0: a rigid contact, measured restitution alpha to 1e-15 (ODE's world CFM 1e-5 gives 0.782 at dt 1e-3 "
            "with the 1 kg ball); ERP 0: the outgoing speed depends on the incoming speed only, never on the overlap "
            "(ERP 0.2 throws a ball resting 1 cm inside the floor 1.4 cm up; in the seeds it only lifts the ball "
            "resting at the end from <= g dt^2 inside the floor onto it)");
        add("world_erp_cfm", fmt::format("ERP {}, CFM {}", num(tuning_.world_erp), num(tuning_.world_cfm)),
            "used by the planar/rotation-lock joints only (contacts use their own); CFM 0 keeps them rigid");
        add("contact_surface_layer", num(tuning_.surface_layer),
            "no tolerated overlap; it only enters the ERP push-out, so with contact ERP 0 it is inert (bit-identical runs with 1 mm)");
        add("contact_max_correcting_vel", num(tuning_.max_correcting_vel),
            "penetration correction may add no speed (ODE's default is infinity); belt and braces with contact ERP 0");
        add("auto_disable", tuning_.auto_disable ? "on" : "off", "ODE's default is off, set off on world and body: on, a ball sliding at 5 mm/s on the floor stops dead after 10 steps");
        add("damping", "linear 0, angular 0, max angular speed inf", "no velocity damping besides the contacts");
        add("ball_mass", fmt::format("{} kg (solid sphere inertia)", num(tuning_.ball_mass)), "only CFM terms depend on the mass, and they are 0");
        add("tangential_model", per_contact ? "per_contact" : "friction",
            per_contact ? "mu = 0; the near callback scales the velocity components along the wall by beta when a ball-wall contact starts (not touching at the previous step)"
                        : "Coulomb friction from the contact joint");
        add("friction_mu", fmt::format("{} (set per contact, no combine rule: the effective mu is this value)", num(mu_)),
            per_contact ? "per_contact model: no friction" : "options.friction (not dInfinity, the samples' value, which makes every contact roll)");
        if (!per_contact)
            add("friction_model",
                fmt::format("{}{}", tuning_.approx1 ? "dContactApprox1 (bound = mu x normal force)" : "Approx0 (mu is a force bound in N)",
                            s.dim == 2 ? ", one row along the in-plane tangent" : (tuning_.align_friction ? ", pyramid aligned with the contact's slip" : ", ODE's default pyramid axes")),
                "Coulomb's law: friction impulse <= mu x normal impulse against the slip (measured to 1e-12 on a sliding bounce). "
                "Approx0 makes mu a force bound in N (0.02 N: 2e-5 m/s per 1 ms step instead of 1.5e-2); ODE's own pyramid "
                "axes turn a diagonal slip by 0.038 rad and take 1.4x the loss");
        add("rotation", options_.free_rotation ? "free" : (s.dim == 2 ? "locked (planar joint angular motor, vel 0, fmax inf)" : "locked (AMotor on 3 world axes, vel 0, fmax inf)"),
            "options.free_rotation");
    }

    static constexpr UnitScale scale_{};  // SI: see the file comment; read() relies on it
    int dim_;
    double alpha_, beta_, h_;
    EngineOptions options_;
    Tuning tuning_;
    double mu_ = 0;

    dWorldID world_ = nullptr;
    dSpaceID space_ = nullptr;
    dJointGroupID contacts_ = nullptr;
    dBodyID body_ = nullptr;
    const dReal* position_ = nullptr;
    const dReal* velocity_ = nullptr;
    dGeomID ball_ = nullptr;
    dJointID plane_ = nullptr;
    dJointID lock_ = nullptr;
    std::vector<Wall> walls_;

    unsigned touching_before_ = 0, touching_now_ = 0;  // bit per wall index
    Stats stats_;
};

}  // namespace

std::unique_ptr<World> build_world(const Scenario& s, const EngineOptions& options, const Tuning& tuning,
                                   std::vector<Setting>& settings) {
    return std::make_unique<OdeWorld>(s, options, tuning, settings);
}

std::unique_ptr<const Simulator> make_simulator(const Tuning& tuning) {
    EngineCapabilities caps;
    caps.planar_2d_in_3d = true;  // ODE's planar joint keeps ODE's x-y plane (see the file comment)
    caps.precision = "double";
    // Debian's libode 0.16 is built without ODE_EXT_ou (no thread-local
    // collision data): dAllocateODEDataForThread does not make its global
    // state per thread, so two ODE worlds must not step at the same time in
    // one process. None do: run, sweep and stress run each pair in a worker
    // process of its own (platform/parallel_pairs.h).
    return make_engine_simulator(
        {kIdentity, caps, [tuning](const Scenario& s, const EngineOptions& options, std::vector<Setting>& settings)
             -> std::unique_ptr<EngineWorld> { return build_world(s, options, tuning, settings); }});
}

}  // namespace ode

std::unique_ptr<const Simulator> make_ode_simulator() { return ode::make_simulator(ode::Tuning::chosen()); }

}  // namespace bouncecheck

// The entry the registry looks up when it loads this adapter's module
// (registry/engine_module.h).
extern "C" const bouncecheck::Simulator* bouncecheck_engine_ode() {
    return bouncecheck::make_ode_simulator().release();
}
