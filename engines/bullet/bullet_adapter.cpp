// Bullet 3.24 in double precision: a sphere (btSphereShape) in a room of
// static planes (btStaticPlaneShape), btDiscreteDynamicsWorld with the
// sequential-impulse solver, one internal step of dt per step().
//
// Every setting below changes the answer at the seed's scale (5 cm ball,
// 0.0981 m/s^2, speeds under 0.5 m/s); each one is reported in the run's
// settings with the reason, and tests/test_bullet.cpp restores each trap's
// default and measures what it does.
#include "engines/bullet/bullet_adapter.h"

#include <btBulletDynamicsCommon.h>

#include <fmt/format.h>

#include <array>
#include <memory>
#include <string>
#include <vector>
#include <cmath>
#include <utility>

static_assert(sizeof(btScalar) == 8,
              "Bullet must be the double-precision build: link pkg-config module bullet-float64 "
              "(BT_USE_DOUBLE_PRECISION and the -float64 libraries)");

namespace bouncecheck {
namespace bullet {
namespace {

// Scenario axis -> engine axis. 3D: the same. 2D (x horizontal, y vertical) runs
// in the engine's x-z plane with the ball locked to y = 0, so Bullet's
// vertical is z in both cases.
int engine_axis(int dim, int axis) { return dim == 3 ? axis : (axis == 0 ? 0 : 2); }

// A dispatcher that gives every new manifold the chosen contact-breaking
// threshold, instead of Bullet's global gContactBreakingThreshold (0.02) times
// the shapes' angular motion disc. No global state is touched.
class Dispatcher final : public btCollisionDispatcher {
public:
    Dispatcher(btCollisionConfiguration* config, btScalar breaking_threshold)
        : btCollisionDispatcher(config), breaking_threshold_(breaking_threshold) {}

    btPersistentManifold* getNewManifold(const btCollisionObject* b0, const btCollisionObject* b1) override {
        btPersistentManifold* m = btCollisionDispatcher::getNewManifold(b0, b1);
        if (breaking_threshold_ >= 0) m->setContactBreakingThreshold(breaking_threshold_);
        return m;
    }

private:
    btScalar breaking_threshold_;
};

// The dynamics world with a hook between this step's narrowphase and its
// solve: the per-contact callback sees this step's manifolds and changes the
// velocity the solver starts from, so beta lands in the same step as the
// restitution impulse. (An internal tick callback runs either before the
// narrowphase, on last step's manifolds, or after the solve and integration:
// one step late.)
class DynamicsWorld final : public btDiscreteDynamicsWorld {
public:
    using btDiscreteDynamicsWorld::btDiscreteDynamicsWorld;
    void set_before_solve(void (*hook)(void*), void* user) {
        hook_ = hook;
        user_ = user;
    }

protected:
    void solveConstraints(btContactSolverInfo& info) override {
        if (hook_) hook_(user_);
        btDiscreteDynamicsWorld::solveConstraints(info);
    }

private:
    void (*hook_)(void*) = nullptr;
    void* user_ = nullptr;
};

std::string num(double x) { return fmt::format("{:.17g}", x); }

// CCD runs when a step moves the ball further than this (m): any real motion.
constexpr double kCcdMotionThreshold = 1e-7;

class BulletWorld final : public World {
public:
    BulletWorld(const Scenario& s, const EngineOptions& options, const Tuning& tuning,
                std::vector<Setting>& settings);
    ~BulletWorld() override;
    BulletWorld(const BulletWorld&) = delete;
    BulletWorld& operator=(const BulletWorld&) = delete;

    void step() override {
        if (tuning_.stepping == Stepping::single_step)
            world_->stepSimulation(dt_, 0);  // variable-step mode: exactly one internal step of dt
        else
            world_->stepSimulation(dt_);  // Bullet's defaults: maxSubSteps 1, fixedTimeStep 1/60
        ++stats_.steps;
    }

    void read(State& out) const override {
        const btVector3& p = ball_->getCenterOfMassPosition();
        const btVector3& v = ball_->getLinearVelocity();
        // Every step: SI units (no scaling); scenario axis 1 is Bullet's z in
        // 2D (engine_axis), and z is 0 there.
        static_assert(scale_.length == 1.0 && scale_.time == 1.0);
        const int second = engine_axis(dim_, 1);
        out.p = Vec3(p[0], p[second], dim_ == 3 ? p[2] : 0.0);
        out.v = Vec3(v[0], v[second], dim_ == 3 ? v[2] : 0.0);
    }

    Vec3 engine_position() const override { return to_vec(ball_->getCenterOfMassPosition()); }
    Vec3 engine_velocity() const override { return to_vec(ball_->getLinearVelocity()); }
    Vec3 engine_angular_velocity() const override { return to_vec(ball_->getAngularVelocity()); }
    Vec3 engine_gravity() const override { return to_vec(ball_->getGravity()); }
    bool ball_active() const override { return ball_->isActive(); }
    const Stats& stats() const override { return stats_; }

private:
    static Vec3 to_vec(const btVector3& v) { return Vec3(v.x(), v.y(), v.z()); }
    static void before_solve_hook(void* self) { static_cast<BulletWorld*>(self)->before_solve(); }
    void before_solve();

    struct EngineWall {
        int engine_axis;
        int side;  // -1 lower wall, +1 upper
        std::unique_ptr<btStaticPlaneShape> shape;
        std::unique_ptr<btRigidBody> body;
    };

    Tuning tuning_;
    int dim_;
    static constexpr UnitScale scale_{1.0, 1.0};  // SI: see "unit_scale" below; read() relies on it
    btScalar dt_;
    bool per_contact_;
    double beta_;
    Stats stats_;

    // Declaration order = reverse destruction order: the world goes first.
    std::unique_ptr<btDefaultCollisionConfiguration> config_;
    std::unique_ptr<Dispatcher> dispatcher_;
    std::unique_ptr<btDbvtBroadphase> broadphase_;
    std::unique_ptr<btSequentialImpulseConstraintSolver> solver_;
    std::unique_ptr<btSphereShape> ball_shape_;
    std::unique_ptr<btRigidBody> ball_;
    std::vector<EngineWall> walls_;
    std::array<bool, 6> touching_{};  // per wall, at the previous solve
    std::unique_ptr<DynamicsWorld> world_;
};

BulletWorld::BulletWorld(const Scenario& s, const EngineOptions& options, const Tuning& tuning,
                         std::vector<Setting>& settings)
    : tuning_(tuning),
      dim_(s.dim),
      dt_(0),
      per_contact_(options.tangential_model == TangentialModel::per_contact),
      beta_(s.beta) {
    auto set = [&settings](std::string key, std::string value, std::string why) {
        settings.push_back({std::move(key), std::move(value), std::move(why)});
    };
    const int version = btGetVersion();
    set("engine", fmt::format("Bullet {}.{:02d} (btGetVersion() = {})", version / 100, version % 100, version),
        "Debian libbullet-dev 3.24+dfsg; btDiscreteDynamicsWorld + btSequentialImpulseConstraintSolver");
    set("precision", fmt::format("double (sizeof(btScalar) = {}, BT_USE_DOUBLE_PRECISION, *-float64 libraries)",
                                 sizeof(btScalar)),
        "pkg-config bullet-float64; checked at configure time and by static_assert: float headers with double "
        "libraries fail silently or crash");

    // Units: SI. Every length-dependent default that matters (contact-breaking
    // threshold, margins, slop, sleeping thresholds) is set explicitly below, and
    // the walls are exact planes, so a scale would change nothing but round-off.
    set("unit_scale", "length 1, time 1 (SI metres and seconds)",
        "double precision and every length-dependent default set explicitly (planes exact, breaking threshold, "
        "slop 0, no sleeping): a scale buys nothing at r = 5 cm");
    dt_ = scale_.to_engine_time(s.dt);

    // --- world ---
    // One ball and six walls: small pools (Bullet's 4096-entry defaults cost
    // milliseconds to allocate per world; the pools grow if ever needed).
    btDefaultCollisionConstructionInfo pools;
    pools.m_defaultMaxPersistentManifoldPoolSize = 16;
    pools.m_defaultMaxCollisionAlgorithmPoolSize = 16;
    config_ = std::make_unique<btDefaultCollisionConfiguration>(pools);
    dispatcher_ = std::make_unique<Dispatcher>(config_.get(), tuning.contact_breaking_threshold);
    broadphase_ = std::make_unique<btDbvtBroadphase>();
    solver_ = std::make_unique<btSequentialImpulseConstraintSolver>();
    world_ = std::make_unique<DynamicsWorld>(dispatcher_.get(), broadphase_.get(), solver_.get(), config_.get());
    world_->set_before_solve(&BulletWorld::before_solve_hook, this);

    btVector3 gravity(0, 0, 0);
    for (int i = 0; i < dim_; ++i) gravity[engine_axis(dim_, i)] = scale_.to_engine_acceleration(s.gravity[i]);
    if (tuning.set_gravity) world_->setGravity(gravity);  // before addRigidBody: the body copies it
    set("gravity", tuning.set_gravity ? fmt::format("({}, {}, {}) m/s^2 (engine frame)", num(gravity.x()),
                                                    num(gravity.y()), num(gravity.z()))
                                      : "Bullet default (0, -10, 0)",
        "btDiscreteDynamicsWorld starts with (0, -10, 0); set before the ball is added (addRigidBody copies the "
        "world's gravity into the body)");

    // --- solver ---
    btContactSolverInfo& si = world_->getSolverInfo();
    si.m_restitutionVelocityThreshold = tuning.restitution_velocity_threshold;
    set("solver.restitution_velocity_threshold", num(tuning.restitution_velocity_threshold),
        "Bullet's 0.2 m/s gives restitution 0 below that incoming speed. Measured in seed-3d: the fourth floor "
        "impact (0.18 m/s) does not bounce and the ball never leaves the back wall (0.1 m/s into it at t = 0). "
        "0 keeps every bounce; the ball then micro-bounces where the model does");
    si.m_splitImpulse = tuning.split_impulse ? 1 : 0;
    si.m_splitImpulsePenetrationThreshold = tuning.split_impulse_penetration_threshold;
    set("solver.split_impulse", tuning.split_impulse ? "on" : "off",
        "penetration is removed by a position-only (push) impulse, not by extra velocity");
    set("solver.split_impulse_penetration_threshold", num(tuning.split_impulse_penetration_threshold),
        "Bullet's -0.04 m splits only penetrations deeper than 4 cm; every shallower one (all of them here) "
        "gets Baumgarte velocity erp2 * depth / dt, which adds energy. Measured restitution at the floor "
        "bounces (should be 0.8): seed-3d 0.82, 0.97, 0.84, 0.99 at dt 0.03 (erp2 0.2), up to 1.71 at "
        "dt 1e-3 with erp2 1. +1e30 splits every contact: 0.8 to round-off");
    si.m_erp2 = tuning.erp2;
    set("solver.erp2", num(tuning.erp2),
        "with split impulse: the fraction of a penetration pushed out per step (no velocity added). 1 removes "
        "it in the step it is found. Bullet's 0.2 leaves the overlap for several steps: 3x the stream's floor "
        "contacts (seed-3d dt 0.03: 133 vs 43); apexes move by < 5 mm either way at dt 0.03, < 0.2 mm at 1e-3");
    si.m_erp = tuning.erp;
    set("solver.erp", num(tuning.erp), "non-contact constraints only; there are none (Bullet default kept)");
    si.m_globalCfm = tuning.global_cfm;
    set("solver.global_cfm", num(tuning.global_cfm), "rigid contacts (Bullet default)");
    si.m_linearSlop = tuning.linear_slop;
    set("solver.linear_slop", num(tuning.linear_slop), "no allowed penetration (Bullet default)");
    si.m_numIterations = tuning.solver_iterations;
    set("solver.iterations", std::to_string(tuning.solver_iterations),
        "one ball, at most three walls: measured identical trajectories with 1, 10 and 100 iterations "
        "(seed-3d, mu 0.3, dt 1e-3)");
    si.m_sor = 1;
    set("solver.sor", "1", "no over-relaxation (Bullet default)");
    si.m_leastSquaresResidualThreshold = 0;
    set("solver.least_squares_residual_threshold", "0", "no early exit from the iterations (Bullet default)");
    si.m_solverMode = SOLVER_SIMD | (tuning.warm_starting ? SOLVER_USE_WARMSTARTING : 0);
    set("solver.warm_starting", tuning.warm_starting ? "on (factor 0.85)" : "off",
        "each step solves its contacts from zero: no impulse carried over from a previous step of a lasting "
        "contact (measured: no difference on the seeds); one friction direction along the slip (Bullet default)");

    // --- walls: static planes ---
    // A btStaticPlaneShape against a sphere is btConvexPlaneCollisionAlgorithm:
    // distance = n . (sphere support point) - constant, exact, with no margin on
    // the plane side and no edges or corners to catch the ball. Static boxes
    // would need their margin (0.04 by default) and size accounted for and go
    // through GJK; planes are the room's walls as the model has them.
    const double wall_restitution = tuning.unit_wall_materials ? 1.0 : 0.0;
    const double wall_friction = tuning.unit_wall_materials ? 1.0 : 0.5;
    for (const Wall& w : room_walls(s)) {
        EngineWall ew;
        ew.engine_axis = engine_axis(dim_, w.axis);
        ew.side = w.side;
        btVector3 normal(0, 0, 0);
        normal[ew.engine_axis] = -w.side;  // facing into the room
        // Plane: normal . x = constant. Lower wall: x = 0; upper: -x = -size.
        const btScalar constant = w.side < 0 ? 0 : -scale_.to_engine_length(w.offset);
        ew.shape = std::make_unique<btStaticPlaneShape>(normal, constant);
        btRigidBody::btRigidBodyConstructionInfo info(0, nullptr, ew.shape.get());
        if (tuning.unit_wall_materials) {
            info.m_restitution = wall_restitution;
            info.m_friction = wall_friction;
        }
        info.m_rollingFriction = 0;
        info.m_spinningFriction = 0;
        ew.body = std::make_unique<btRigidBody>(info);
        ew.body->setUserIndex(static_cast<int>(walls_.size()));
        walls_.push_back(std::move(ew));
    }
    set("walls", fmt::format("{} static btStaticPlaneShape at x_i = 0 and x_i = size_i (contact surface exactly there)",
                             walls_.size()),
        "sphere-plane distance is exact (no wall margin, no GJK, no edges); boxes carry a 0.04 margin and corners");
    set("wall.restitution", num(wall_restitution),
        tuning.unit_wall_materials ? "Bullet combines restitution as the product of the two bodies': walls 1, ball "
                                     "alpha gives alpha (Bullet's default 0 gives no bounce at all)"
                                   : "Bullet default: the product with the ball's is 0, no bounce");
    set("wall.friction", num(wall_friction),
        "Bullet combines friction as the product (clamped to 10): walls 1, ball mu gives mu");
    set("wall.rolling_friction", "0", "no rolling or spinning resistance: the model has none");

    // --- ball ---
    const double r = scale_.to_engine_length(s.radius);
    ball_shape_ = std::make_unique<btSphereShape>(r);
    set("ball.shape", fmt::format("btSphereShape r = {} m, margin = radius", num(r)),
        "a sphere is a point inflated by its margin, so its surface is exactly at r (no extra margin to set)");
    const btScalar mass = 1;
    btVector3 inertia(0, 0, 0);
    ball_shape_->calculateLocalInertia(mass, inertia);
    const double ball_friction = per_contact_ ? 0.0 : options.friction;
    btRigidBody::btRigidBodyConstructionInfo info(mass, nullptr, ball_shape_.get(), inertia);
    info.m_restitution = s.alpha;
    info.m_friction = ball_friction;
    info.m_rollingFriction = 0;
    info.m_spinningFriction = 0;
    info.m_linearDamping = 0;
    info.m_angularDamping = 0;
    info.m_additionalDamping = false;
    btTransform start;
    start.setIdentity();
    btVector3 p0(0, 0, 0), v0(0, 0, 0);
    for (int i = 0; i < dim_; ++i) {
        p0[engine_axis(dim_, i)] = scale_.to_engine_length(s.position[i]);
        v0[engine_axis(dim_, i)] = scale_.to_engine_velocity(s.velocity[i]);
    }
    start.setOrigin(p0);
    info.m_startWorldTransform = start;
    ball_ = std::make_unique<btRigidBody>(info);
    ball_->setLinearVelocity(v0);
    ball_->setAngularVelocity(btVector3(0, 0, 0));
    ball_->setFlags(0);  // no gyroscopic term (zero for a sphere anyway), world gravity applies
    set("ball.mass", "1 kg, inertia 2/5 m r^2 (solid sphere)", "the law is mass-free; inertia matters only with "
        "friction and free rotation");
    set("ball.restitution", num(s.alpha), "x wall 1 (product) = alpha");
    set("ball.friction", num(ball_friction),
        per_contact_ ? "per_contact: mu = 0, beta is applied by the contact hook"
                     : "x wall 1 (product) = mu, the scenario's [engines.bullet] friction");
    set("ball.damping", "linear 0, angular 0, additional damping off", "the model has no air drag");

    const bool free_rotation = options.free_rotation;
    if (dim_ == 2) {
        ball_->setLinearFactor(btVector3(1, 0, 1));
        ball_->setAngularFactor(free_rotation ? btVector3(0, 1, 0) : btVector3(0, 0, 0));
        set("planar_2d", "scenario (x, y) -> engine (x, z); linear factor (1, 0, 1), no walls on y",
            "the ball stays in the y = 0 plane; Bullet's vertical is z as in 3D");
    } else {
        ball_->setAngularFactor(free_rotation ? btVector3(1, 1, 1) : btVector3(0, 0, 0));
    }
    set("ball.rotation",
        free_rotation ? (dim_ == 2 ? "free about the plane's normal (angular factor (0, 1, 0))" : "free")
                      : "locked (angular factor 0)",
        "scenario [engines.bullet] free_rotation");

    // The scenario's ccd switches CCD on with a threshold below any motion
    // that matters, or off; unset keeps the tuning's.
    const double ccd_threshold = !options.ccd    ? tuning.ccd_motion_threshold
                                 : *options.ccd ? (tuning.ccd_motion_threshold > 0 ? tuning.ccd_motion_threshold
                                                                                   : kCcdMotionThreshold)
                                                : 0.0;
    if (ccd_threshold > 0) {
        ball_->setCcdMotionThreshold(scale_.to_engine_length(ccd_threshold));
        ball_->setCcdSweptSphereRadius(r);
        // The sweep ignores a hit unless the step moves the ball more than
        // this far into the wall (btClosestNotMeConvexResultCallback).
        world_->getDispatchInfo().m_allowedCcdPenetration = 0;
    }
    set("ccd", ccd_threshold > 0 ? fmt::format("motion threshold {} m, swept sphere radius r, allowed CCD "
                                               "penetration 0 (Bullet: 0.04 m)", num(ccd_threshold))
                                 : "off (motion threshold 0)",
        options.ccd ? "scenario [engines.bullet] ccd. Allowed CCD penetration 0: with Bullet's 0.04 m the sweep "
                      "ignores every step that moves the ball less than 4 cm into a wall (measured: the 1 mm ball of "
                      "stress/tiny-ball-ccd ends 4 mm beyond the wall, as without CCD)"
                    : "a step moves the ball at most 1.4 cm (0.45 m/s x 0.03 s) < r: no tunnelling. Measured: CCD on "
                      "(threshold 1e-7, swept radius r) changes nothing on the seeds at dt 0.03 and 1e-3");

    world_->addRigidBody(ball_.get());
    for (auto& w : walls_) world_->addRigidBody(w.body.get());
    if (tuning.disable_deactivation) ball_->forceActivationState(DISABLE_DEACTIVATION);
    set("sleeping", tuning.disable_deactivation ? "off (DISABLE_DEACTIVATION)" : "Bullet default (0.8 m/s, 2 s)",
        "Bullet puts a ball slower than 0.8 m/s for 2 s to sleep: both seed balls freeze mid-air at t = 2 s "
        "(z = 0.70 in seed-3d) and never reach the floor");

    set("contact_breaking_threshold",
        tuning.contact_breaking_threshold >= 0 ? fmt::format("{} m (every ball-wall manifold)",
                                                             num(tuning.contact_breaking_threshold))
                                               : "Bullet default (0.02 x angular motion disc = 1.73 mm)",
        "a point within this gap is a speculative contact: the solver lets the ball close the gap in the step, "
        "then bounces it with alpha u - gap / dt. Bullet's 1.73 mm eats up to gap / dt of the bounce (1.7 m/s at "
        "dt = 1e-3): measured restitution 0.28, 0.58, 0.38 then the ball stays on the floor (seed-3d, "
        "dt 1e-3), 0.57 and 0.55 at dt 0.03. 1e-9 m costs at most 1e-6 m/s at dt = 1e-3 and still catches "
        "a ball that starts touching a wall (seed-3d)");
    set("contact_processing_threshold", "Bullet default (BT_LARGE_FLOAT): every manifold point is solved",
        "the breaking threshold alone decides what is a contact");

    set("stepping",
        tuning.stepping == Stepping::single_step ? fmt::format("stepSimulation(dt = {}, maxSubSteps = 0)", num(dt_))
                                                 : "stepSimulation(dt) (maxSubSteps 1, fixedTimeStep 1/60)",
        "maxSubSteps = 0 is Bullet's variable-step mode: exactly one internal step of dt, no interpolation. The "
        "default arguments step a fixed 1/60 s at most once per call (dt = 0.03 runs at 0.56x speed; dt = 1e-3 "
        "steps once every 17 calls)");

    set("tangential_model",
        per_contact_ ? fmt::format("per_contact: a pre-solve hook scales the ball's tangential velocity by beta = {} "
                                   "when a ball-wall manifold gains its first point while the ball moves into that wall",
                                   num(beta_))
                     : fmt::format("friction: Coulomb mu = {} (one friction direction, along the slip)",
                                   num(options.friction)),
        per_contact_ ? "once at the start of each contact, in the same step as the restitution impulse"
                     : "the scenario's [engines.bullet] table");
}

BulletWorld::~BulletWorld() {
    if (world_) {
        world_->removeRigidBody(ball_.get());
        for (auto& w : walls_) world_->removeRigidBody(w.body.get());
    }
}

void BulletWorld::before_solve() {
    std::array<bool, 6> now{};
    btDispatcher* d = world_->getDispatcher();
    for (int i = 0; i < d->getNumManifolds(); ++i) {
        btPersistentManifold* m = d->getManifoldByIndexInternal(i);
        if (m->getNumContacts() == 0) continue;
        const btCollisionObject* other = m->getBody0() == ball_.get()   ? m->getBody1()
                                         : m->getBody1() == ball_.get() ? m->getBody0()
                                                                        : nullptr;
        if (!other || other->getUserIndex() < 0) continue;
        now[static_cast<std::size_t>(other->getUserIndex())] = true;
    }
    bool any = false;
    for (std::size_t w = 0; w < walls_.size(); ++w) {
        any = any || now[w];
        if (!now[w] || touching_[w]) continue;
        ++stats_.new_wall_contacts;
        btVector3 v = ball_->getLinearVelocity();
        // Bullet reports a ball resting against a wall at distance 0 (seed-2d's
        // ceiling at t = 0) as touching: the law's condition decides.
        const int axis = walls_[w].engine_axis;
        if (per_contact_ && moves_into_wall(v[axis], ball_->getGravity()[axis], walls_[w].side)) {
            for (int a = 0; a < 3; ++a)
                if (a != walls_[w].engine_axis) v[a] *= beta_;
            ball_->setLinearVelocity(v);
        }
    }
    if (any) ++stats_.touching_steps;
    touching_ = now;
}

}  // namespace

std::unique_ptr<World> build_world(const Scenario& s, const EngineOptions& options, const Tuning& tuning,
                                   std::vector<Setting>& settings) {
    return std::make_unique<BulletWorld>(s, options, tuning, settings);
}

std::unique_ptr<const Simulator> make_simulator(const Tuning& tuning) {
    EngineCapabilities caps;
    caps.planar_2d_in_3d = true;
    caps.precision = "double";
    return make_engine_simulator(
        {kIdentity, caps, [tuning](const Scenario& s, const EngineOptions& options, std::vector<Setting>& settings)
             -> std::unique_ptr<EngineWorld> { return build_world(s, options, tuning, settings); }});
}

}  // namespace bullet

std::unique_ptr<const Simulator> make_bullet_simulator() { return bullet::make_simulator(bullet::Tuning::chosen()); }

}  // namespace bouncecheck

// The entry the registry looks up when it loads this adapter's module
// (registry/engine_module.h).
extern "C" const bouncecheck::Simulator* bouncecheck_engine_bullet() {
    return bouncecheck::make_bullet_simulator().release();
}
