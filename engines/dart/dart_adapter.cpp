// DART 6.12 (double precision): the ball is a sphere on a FreeJoint (3D),
// PlanarJoint (2D, x-y plane) or a translational joint when rotation is
// locked; the room is one fixed skeleton whose body carries a thick box per
// wall. One World::step of dt is one engine step. Every setting that changes
// the answer is chosen here and reported; see engines/dart/dart_adapter.h for
// the defaults they replace.
//
// How a bounce happens in DART 6.12 (World.cpp, ConstraintSolver.cpp,
// ContactConstraint.cpp): World::step first integrates velocities
// (v += g dt), then the constraint solver runs collision detection at the
// positions the step starts from and solves one LCP over the contacts, then
// positions are integrated with the new velocity (x += v dt): semi-implicit
// Euler, contacts found one step late compared with the document's clamp. A
// contact's target normal velocity is the larger of e |v_n| (v_n after this
// step's gravity, e = e_ball x e_wall) and the penetration correction
// ERP depth / dt (at most the max error reduction velocity); restitution
// applies only when e |v_n| > 0.1 and is capped at 100 (compile-time
// constants, model units). Friction is the smaller of the two shapes' mu,
// and off below mu = 1e-3.
//
// Axes: scenario (x, y, z) = DART (x, y, z) in 3D, scenario (x, y) = DART
// (x, y) in 2D, gravity as the scenario gives it. Units: lengths times
// length_scale_for() (time unscaled).
#include "engines/dart/dart_adapter.h"

#include <dart/collision/CollisionGroup.hpp>
#include <dart/collision/CollisionObject.hpp>
#include <dart/collision/CollisionResult.hpp>
#include <dart/collision/dart/DARTCollisionDetector.hpp>
#include <dart/collision/fcl/FCLCollisionDetector.hpp>
#include <dart/config.hpp>
#include <dart/constraint/BoxedLcpConstraintSolver.hpp>
#include <dart/constraint/ConstraintSolver.hpp>
#include <dart/constraint/ContactConstraint.hpp>
#include <dart/constraint/DantzigBoxedLcpSolver.hpp>
#include <dart/constraint/PgsBoxedLcpSolver.hpp>
#include <dart/dynamics/BodyNode.hpp>
#include <dart/dynamics/BoxShape.hpp>
#include <dart/dynamics/FreeJoint.hpp>
#include <dart/dynamics/PlanarJoint.hpp>
#include <dart/dynamics/ShapeNode.hpp>
#include <dart/dynamics/Skeleton.hpp>
#include <dart/dynamics/SphereShape.hpp>
#include <dart/dynamics/TranslationalJoint.hpp>
#include <dart/dynamics/TranslationalJoint2D.hpp>
#include <dart/dynamics/WeldJoint.hpp>
#include <dart/simulation/World.hpp>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

static_assert(DART_MAJOR_VERSION == 6 && DART_MINOR_VERSION == 12,
              "the adapter's settings and DART's constants were read and measured on DART 6.12");

namespace bouncecheck {
namespace dartsim {

double length_scale_for(const Scenario& s, const Tuning& t) {
    if (t.length_scale > 0) return t.length_scale;
    // A resting ball hops at the fixed point u = e |g| dt / (1 - e) of
    // "fall one step, bounce with e": it settles only if e |v_n| stays below
    // DART's threshold there, i.e. u L < 0.1 (model units). Keep it below by
    // rest_margin. e / (1 - e) is capped at 10 (e = 10/11): a ball with
    // alpha near 1 hardly rests, and the cap keeps its scale usable.
    const double e = std::clamp(s.alpha, 0.0, 1.0);
    const double growth = std::min(e / std::max(1 - e, 1e-12), 10.0);
    const double rest_hop = growth * s.gravity.norm() * s.dt;
    double scale = t.max_length_scale;
    if (rest_hop > 0) scale = std::min(scale, kBouncingVelocityThreshold / (t.rest_margin * rest_hop));
    // The fastest bounce (the energy bound) must stay below DART's cap of 100.
    const double v_max = max_ball_speed(s);
    if (v_max > 0) scale = std::min(scale, kMaxBouncingVelocity / (2 * v_max));
    return scale;
}

namespace {

namespace dd = ::dart::dynamics;
namespace dc = ::dart::collision;
namespace dk = ::dart::constraint;

std::string num(double x) { return fmt::format("{:.6g}", x); }

const char* detector_name(Detector d) {
    switch (d) {
        case Detector::dart: return "DARTCollisionDetector (analytic sphere-box)";
        case Detector::fcl_primitive: return "FCL, PRIMITIVE (analytic sphere)";
        case Detector::fcl_mesh: return "FCL, MESH (sphere tessellated)";
    }
    return "?";
}

struct EngineWall {
    Wall wall;
    const dd::ShapeFrame* shape = nullptr;
};

class DartWorld final : public World {
public:
    DartWorld(const Scenario& s, const EngineOptions& options, const Tuning& t, std::vector<Setting>& settings)
        : tuning_(t), dim_(s.dim), beta_(s.beta), scale_(length_scale_for(s, t)),
          per_contact_(options.tangential_model == TangentialModel::per_contact) {
        const double L = scale_;
        const double mu = per_contact_ ? 0.0 : options.friction;
        free_rotation_ = options.free_rotation;

        world_ = ::dart::simulation::World::create("bouncecheck");
        if (t.set_timestep) world_->setTimeStep(s.dt);
        if (t.set_gravity) world_->setGravity(s.gravity * L);

        // The room: one fixed body, a box per wall, its inner face on the
        // wall, thick enough that one step cannot carry the ball's centre
        // through it (twice the largest step the law allows, at least half
        // the room's larger side), long enough to run past the corners.
        const double max_step = max_ball_speed(s) * s.dt;
        const double largest_side = std::max({s.room.x(), s.room.y(), s.dim == 3 ? s.room.z() : 0.0});
        wall_thickness_ = std::max(largest_side / 2, 2 * max_step);
        auto room = dd::Skeleton::create("room");
        dd::BodyNode* room_body = room->createJointAndBodyNodePair<dd::WeldJoint>().second;
        for (const Wall& w : room_walls(s)) {
            Vec3 size, centre;
            for (int a = 0; a < 3; ++a) {
                const double extent = a < s.dim ? s.room[a] : largest_side;
                size[a] = extent + 2 * (wall_thickness_ + s.radius);
                centre[a] = a < s.dim ? s.room[a] / 2 : 0.0;
            }
            size[w.axis] = wall_thickness_;
            centre[w.axis] = w.offset + w.side * wall_thickness_ / 2;
            auto box = std::make_shared<dd::BoxShape>(Eigen::Vector3d(size * L));
            auto* node = room_body->createShapeNodeWith<dd::CollisionAspect, dd::DynamicsAspect>(box);
            node->setRelativeTranslation(centre * L);
            node->getDynamicsAspect()->setRestitutionCoeff(t.wall_restitution);
            node->getDynamicsAspect()->setFrictionCoeff(mu);
            walls_.push_back({w, node});
        }
        room->setMobile(false);

        // The ball: mass 1, a solid sphere's inertia; its body origin is the centre.
        auto ball = dd::Skeleton::create("ball");
        dd::BodyNode::Properties body;
        body.mName = "ball";
        const double r = s.radius * L;
        body.mInertia = dd::Inertia(1.0, Eigen::Vector3d::Zero(), dd::SphereShape::computeInertia(r, 1.0));
        const Eigen::Vector3d p = s.position * L;
        const Eigen::Vector3d v = s.velocity * L;
        if (s.dim == 3 && free_rotation_) {
            auto pair = ball->createJointAndBodyNodePair<dd::FreeJoint>(nullptr, dd::FreeJoint::Properties(), body);
            auto* joint = pair.first;
            Eigen::Isometry3d tf = Eigen::Isometry3d::Identity();
            tf.translation() = p;
            joint->setPositions(dd::FreeJoint::convertToPositions(tf));
            joint->setLinearVelocity(v);
            ball_ = pair.second;
            joint_ = joint;
        } else if (s.dim == 3) {
            auto pair =
                ball->createJointAndBodyNodePair<dd::TranslationalJoint>(nullptr, dd::TranslationalJoint::Properties(), body);
            pair.first->setPositions(p);
            pair.first->setVelocities(v);
            ball_ = pair.second;
            joint_ = pair.first;
        } else if (free_rotation_) {
            auto pair = ball->createJointAndBodyNodePair<dd::PlanarJoint>(nullptr, dd::PlanarJoint::Properties(), body);
            pair.first->setXYPlane();
            pair.first->setPositions(Eigen::Vector3d(p.x(), p.y(), 0.0));
            pair.first->setVelocities(Eigen::Vector3d(v.x(), v.y(), 0.0));
            ball_ = pair.second;
            joint_ = pair.first;
        } else {
            auto pair = ball->createJointAndBodyNodePair<dd::TranslationalJoint2D>(
                nullptr, dd::TranslationalJoint2D::Properties(), body);
            pair.first->setXYPlane();
            pair.first->setPositions(Eigen::Vector2d(p.x(), p.y()));
            pair.first->setVelocities(Eigen::Vector2d(v.x(), v.y()));
            ball_ = pair.second;
            joint_ = pair.first;
        }
        auto* ball_shape = ball_->createShapeNodeWith<dd::CollisionAspect, dd::DynamicsAspect>(
            std::make_shared<dd::SphereShape>(r));
        ball_shape->getDynamicsAspect()->setRestitutionCoeff(s.alpha);
        ball_shape->getDynamicsAspect()->setFrictionCoeff(mu);
        ball_friction_ = ball_shape->getDynamicsAspect();
        ball_friction_->setFirstFrictionDirectionFrame(dd::Frame::World());
        align_friction_ = !per_contact_ && t.friction_along_slip && mu > 0;

        world_->addSkeleton(room);
        world_->addSkeleton(ball);

        dk::ConstraintSolver* solver = world_->getConstraintSolver();
        if (t.detector == Detector::dart) {
            solver->setCollisionDetector(dc::DARTCollisionDetector::create());
        } else {
            auto fcl = dc::FCLCollisionDetector::create();
            fcl->setPrimitiveShapeType(t.detector == Detector::fcl_primitive ? dc::FCLCollisionDetector::PRIMITIVE
                                                                              : dc::FCLCollisionDetector::MESH);
            solver->setCollisionDetector(fcl);
        }
        solver->getCollisionOption().maxNumContacts = t.max_contacts;
        auto* boxed = dynamic_cast<dk::BoxedLcpConstraintSolver*>(solver);
        if (!boxed) throw std::runtime_error("DART's world constraint solver is not a BoxedLcpConstraintSolver");
        auto pgs = std::make_shared<dk::PgsBoxedLcpSolver>();
        dk::PgsBoxedLcpSolver::Option pgs_option = pgs->getOption();
        pgs_option.mMaxIteration = t.pgs_iterations;
        pgs->setOption(pgs_option);
        if (t.lcp == LcpSolver::dantzig) {
            boxed->setBoxedLcpSolver(std::make_shared<dk::DantzigBoxedLcpSolver>());
            boxed->setSecondaryBoxedLcpSolver(pgs);
        } else {
            boxed->setBoxedLcpSolver(pgs);
            boxed->setSecondaryBoxedLcpSolver(nullptr);
        }

        report(s, options, mu, settings);
    }

    void step() override {
        // ContactConstraint's correction parameters are static members: set
        // before every step, so that worlds of different tunings stepped in
        // turn on one thread each get their own.
        dk::ContactConstraint::setErrorReductionParameter(tuning_.error_reduction);
        dk::ContactConstraint::setMaxErrorReductionVelocity(tuning_.max_error_reduction_velocity);
        dk::ContactConstraint::setErrorAllowance(tuning_.error_allowance);
        dk::ContactConstraint::setConstraintForceMixing(tuning_.constraint_force_mixing);
        const Eigen::Vector3d start_velocity = ball_->getLinearVelocity();
        // ContactConstraint takes the tangent basis's first direction as the
        // projection of this one on the contact plane (a vertical drop falls
        // back to DART's fixed basis, where there is no slip to bound).
        if (align_friction_ && start_velocity.squaredNorm() > 0)
            ball_friction_->setFirstFrictionDirection(start_velocity.normalized());
        if (per_contact_ && tuning_.beta_before_step) apply_beta(touching_walls_now(), start_velocity);
        world_->step();
        ++stats_.steps;
        const dc::CollisionResult& found = world_->getLastCollisionResult();
        stats_.max_contacts = std::max(stats_.max_contacts, found.getNumContacts());
        // After the step the contact has turned the ball: the law's condition
        // reads the velocity the step started from.
        if (per_contact_ && !tuning_.beta_before_step) apply_beta(walls_in(found), start_velocity);
    }

    void read(State& out) const override {
        const Eigen::Vector3d p = ball_->getWorldTransform().translation() / scale_;
        const Eigen::Vector3d v = ball_->getLinearVelocity() / scale_;
        out.p = Vec3(p.x(), p.y(), dim_ == 3 ? p.z() : 0.0);
        out.v = Vec3(v.x(), v.y(), dim_ == 3 ? v.z() : 0.0);
    }

    const Stats& stats() const override { return stats_; }
    double length_scale() const override { return scale_; }
    double spin() const override { return ball_->getAngularVelocity().norm(); }

private:
    unsigned walls_in(const dc::CollisionResult& result) const {
        unsigned mask = 0;
        for (const dc::Contact& c : result.getContacts()) {
            const dd::ShapeFrame* a = c.collisionObject1->getShapeFrame();
            const dd::ShapeFrame* b = c.collisionObject2->getShapeFrame();
            for (std::size_t w = 0; w < walls_.size(); ++w)
                if (walls_[w].shape == a || walls_[w].shape == b) mask |= 1u << w;
        }
        return mask;
    }

    // The contacts this step's own detection will find: nothing moves the
    // ball between here and World::step's collide (velocity integration
    // leaves positions alone).
    unsigned touching_walls_now() {
        dc::CollisionResult result;
        dk::ConstraintSolver* solver = world_->getConstraintSolver();
        solver->getCollisionGroup()->collide(solver->getCollisionOption(), &result);
        return walls_in(result);
    }

    // Per-contact beta: a wall the ball touches now and did not at the
    // previous check starts a contact; if the law counts it (judged on
    // `judged`, the velocity the step starts with), every velocity component
    // of the ball but that wall's normal is scaled by beta, once.
    void apply_beta(unsigned now, const Eigen::Vector3d& judged) {
        const Eigen::Vector3d g = world_->getGravity();
        for (std::size_t w = 0; w < walls_.size(); ++w) {
            if (!((now >> w) & 1u) || ((touching_ >> w) & 1u)) continue;
            ++stats_.new_wall_contacts;
            const Wall& wall = walls_[w].wall;
            if (!moves_into_wall(judged[wall.axis], g[wall.axis], wall.side)) continue;
            Eigen::Vector3d v = ball_->getLinearVelocity();
            for (int a = 0; a < 3; ++a)
                if (a != wall.axis) v[a] *= beta_;
            set_linear_velocity(v);
            ++stats_.beta_applied;
        }
        touching_ = now;
    }

    void set_linear_velocity(const Eigen::Vector3d& v) {
        if (auto* free = dynamic_cast<dd::FreeJoint*>(joint_)) {
            free->setLinearVelocity(v);
        } else if (dim_ == 3) {
            joint_->setVelocities(v);
        } else {
            // PlanarJoint (x, y, theta) or TranslationalJoint2D (x, y): the
            // first two are the translation's, in the world's x-y plane.
            joint_->setVelocity(0, v.x());
            joint_->setVelocity(1, v.y());
        }
    }

    void report(const Scenario& s, const EngineOptions& options, double mu, std::vector<Setting>& out) const;

    Tuning tuning_;
    int dim_;
    double beta_;
    double scale_;
    bool per_contact_;
    bool free_rotation_ = true;
    double wall_thickness_ = 0;
    ::dart::simulation::WorldPtr world_;
    dd::BodyNode* ball_ = nullptr;
    dd::Joint* joint_ = nullptr;
    dd::DynamicsAspect* ball_friction_ = nullptr;
    bool align_friction_ = false;
    std::vector<EngineWall> walls_;
    unsigned touching_ = 0;  // bit per wall, at the previous check
    Stats stats_;
};

void DartWorld::report(const Scenario& s, const EngineOptions& options, double mu, std::vector<Setting>& out) const {
    auto set = [&out](std::string key, std::string value, std::string why) {
        out.push_back({std::move(key), std::move(value), std::move(why)});
    };
    const Tuning& t = tuning_;
    const double L = scale_;
    const double e = s.alpha * t.wall_restitution;
    set("engine", fmt::format("DART {} (DART_VERSION)", DART_VERSION),
        "Debian libdart-dev; only the core component is linked (DARTCollisionDetector and FCL are in libdart)");
    set("precision", "double", "DART's scalars are double throughout (Eigen::Vector3d)");
    set("length_scale",
        fmt::format("{} (model units = scenario metres x {})", num(L), num(L)),
        t.length_scale > 0
            ? "fixed by the tuning"
            : fmt::format("rule: min({}, 0.1 / ({} e |g| dt / (1 - e)), 100 / (2 v_max)) with e / (1 - e) capped at "
                          "10: DART bounces only when e |v_n| > 0.1 model units/s, and a ball at rest hops at "
                          "u = e |g| dt / (1 - e) (here {} m/s); the scale keeps u {}x below the threshold so the "
                          "ball settles, and as large as that allows so slower bounces still bounce (threshold "
                          "here: e |v_n| > {} m/s). The fastest bounce the law allows stays below DART's cap of "
                          "100 model units/s. DART at scale 1: seed-3d's floor bounces stop after 6",
                          num(t.max_length_scale), num(t.rest_margin),
                          num(std::min(e / std::max(1 - e, 1e-12), 10.0) * s.gravity.norm() * s.dt),
                          num(t.rest_margin), num(kBouncingVelocityThreshold / L)));
    set("timestep",
        t.set_timestep ? fmt::format("{} s (World::setTimeStep(dt))", num(world_->getTimeStep()))
                       : fmt::format("{} s (DART default)", num(world_->getTimeStep())),
        "one World::step per engine step, and it advances the world's time step: DART's default 0.001 s would run "
        "the scene at 0.001 / dt of its speed");
    const Eigen::Vector3d g = world_->getGravity();
    set("gravity",
        fmt::format("({}, {}, {}) model units/s^2{}", num(g.x()), num(g.y()), num(g.z()),
                    t.set_gravity ? " (the scenario's x length_scale)" : " (DART default)"),
        "DART's default is (0, 0, -9.81), 100x the seeds' and along z");
    set("joints",
        dim_ == 3 ? (free_rotation_ ? "FreeJoint (6 dof)" : "TranslationalJoint (3 dof, rotation locked)")
                  : (free_rotation_ ? "PlanarJoint, x-y plane (x, y, rotation about z)"
                                    : "TranslationalJoint2D, x-y plane (rotation locked)"),
        dim_ == 3 ? "3D: scenario axes are DART's" : "2D: the ball cannot leave z = 0; the planar joint keeps its spin");
    set("collision_detector", detector_name(t.detector),
        t.detector == Detector::dart
            ? "DART's default is FCL with the sphere as a mesh (MESH): its facets spin the ball (0.75 rad/s on "
              "seed-3d), sink it 3.9 mm and move apexes 4 and 5 by +18.6% and -59%. DARTCollisionDetector's "
              "sphere-box test is exact (DART warns that FCL PRIMITIVE is incomplete: not used)"
            : "not the adapter's choice");
    set("restitution", fmt::format("ball {} x walls {} = {}", num(s.alpha), num(t.wall_restitution), num(e)),
        "ContactConstraint takes the product; DART's default coefficient is 0, so walls left unset never bounce");
    set("restitution_threshold",
        fmt::format("e |v_n| > {} model units/s = {} m/s; capped at {} model units/s = {} m/s",
                    num(kBouncingVelocityThreshold), num(kBouncingVelocityThreshold / L), num(kMaxBouncingVelocity),
                    num(kMaxBouncingVelocity / L)),
        "compile-time constants of ContactConstraint.cpp (DART_BOUNCING_VELOCITY_THRESHOLD, "
        "DART_MAX_BOUNCING_VELOCITY); below the threshold a contact is inelastic. e |v_n| uses the normal velocity "
        "after the step's gravity");
    set("friction", fmt::format("ball {} walls {} (min: {})", num(mu), num(mu), num(mu)),
        per_contact_ ? "per-contact mode: mu = 0 on both (DART's default is 1), beta applied by the step hook"
                     : (mu > 1e-3 ? "the scenario's [engines.dart] friction on both shapes; DART takes the smaller"
                                  : "the scenario's friction is at or below DART_FRICTION_COEFF_THRESHOLD 1e-3: DART "
                                    "turns friction off for the contact"));
    set("friction_direction",
        align_friction_ ? "the ball's velocity, set as its first friction direction (world frame) before every step"
                        : "DART's fixed basis",
        "DART's cone is a pyramid: two tangent directions, each bounded by mu N on its own. Its default basis is "
        "fixed (x and y on a floor): a 2:1 diagonal slide turns to 0.4866 where Coulomb keeps 0.5. Along the slip "
        "the edge bounds the sliding force at mu N and the other direction has no slip: Coulomb's for a slide");
    set("contact.error_reduction",
        fmt::format("ERP {}, max error reduction velocity {} model units/s ({} m/s), error allowance {} model units, "
                    "CFM {}",
                    num(t.error_reduction), num(t.max_error_reduction_velocity),
                    num(t.max_error_reduction_velocity / L), num(t.error_allowance), num(t.constraint_force_mixing)),
        "DART 6.12's defaults (DART_ERP 0.01, DART_MAX_ERV 1e-3, DART_ERROR_ALLOWANCE 0, DART_CFM 1e-5), set "
        "explicitly before every step (process-wide statics of ContactConstraint). Penetration is corrected through "
        "the contact's target velocity (ERP depth / dt, at most the max velocity): it adds speed, there is no split "
        "impulse in DART 6.12; a bounce takes the larger of that and e |v_n|");
    set("lcp_solver",
        t.lcp == LcpSolver::dantzig
            ? fmt::format("BoxedLcpConstraintSolver: Dantzig, PGS ({} iterations) if Dantzig fails", t.pgs_iterations)
            : fmt::format("BoxedLcpConstraintSolver: PGS only, {} iterations", t.pgs_iterations),
        "DART's default pair, set explicitly; one ball and at most three contacts: Dantzig is exact");
    set("max_contacts", fmt::format("{} (CollisionOption::maxNumContacts)", t.max_contacts),
        "DART's default; the ball touches at most three walls, one contact each with an analytic sphere");
    set("walls",
        fmt::format("{} boxes on one fixed body (Skeleton::setMobile(false)), {} m thick, inner faces on the walls",
                    walls_.size(), num(wall_thickness_)),
        "thick walls (half the room's larger side, at least two of the largest steps the law allows): the ball's "
        "centre cannot cross a box in one step");
    set("ball", fmt::format("sphere r = {} m ({} model units), mass 1, inertia 2/5 m r^2", num(s.radius),
                            num(s.radius * L)),
        "mass cancels out against fixed walls");
    set("sleeping", "none", "DART 6.12 has no sleeping or deactivation");
    set("ccd", "none",
        "DART has no continuous collision detection; contacts are found at the step's starting positions: "
        "substeps shorten the travel");
    set("threads", "one world at a time per process (ContactConstraint's ERP, max velocity, allowance and CFM are "
                   "static members)",
        "every world writes them before its step; two threads stepping worlds would race on them, so run, sweep "
        "and stress give each run a worker process of its own");
    set("tangential_model",
        per_contact_ ? fmt::format("per-contact: beta = {} on the ball's velocity along the wall, {}", num(beta_),
                                   t.beta_before_step
                                       ? "before the step whose collision detection first finds the contact "
                                         "(a collision query at the step's starting position): the step's solve "
                                         "and position update use the scaled velocity"
                                       : "after the step that found the contact (not the adapter's choice)")
                     : fmt::format("friction: Coulomb mu = {}", num(mu)),
        per_contact_ ? "once when a contact starts (a wall box absent from the previous check's contacts) and the "
                       "ball moves into the wall (moves_into_wall)"
                     : "the scenario's [engines.dart] table");
    set("free_rotation", options.free_rotation ? "true" : "false", "scenario [engines.dart] rotation");
}

}  // namespace

std::unique_ptr<World> build_world(const Scenario& s, const EngineOptions& options, const Tuning& tuning,
                                   std::vector<Setting>& settings) {
    return std::make_unique<DartWorld>(s, options, tuning, settings);
}

std::unique_ptr<const Simulator> make_simulator(const Tuning& tuning) {
    EngineCapabilities caps;
    caps.planar_2d_in_3d = true;
    caps.precision = "double";
    // DART 6.12 keeps ContactConstraint's error reduction parameter, max
    // error reduction velocity, error allowance and constraint force mixing in
    // static members, written by every world before its step: one world steps
    // at a time per process (each pair runs in a worker process of its own).
    return make_engine_simulator(
        {kIdentity, caps, [tuning](const Scenario& s, const EngineOptions& options, std::vector<Setting>& settings)
             -> std::unique_ptr<EngineWorld> { return build_world(s, options, tuning, settings); }});
}

}  // namespace dartsim

std::unique_ptr<const Simulator> make_dart_simulator() { return dartsim::make_simulator(dartsim::Tuning{}); }

}  // namespace bouncecheck

// The entry the registry looks up when it loads this adapter's module
// (registry/engine_module.h).
extern "C" const bouncecheck::Simulator* bouncecheck_engine_dart() {
    return bouncecheck::make_dart_simulator().release();
}
