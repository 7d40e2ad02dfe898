// Box2D 2.4.1 (2D only, single precision): the ball is a dynamic circle, the
// room four static boxes. Every setting that changes the answer is chosen here
// and reported; see engines/box2d/box2d_adapter.h for the defaults they replace.
//
// How a bounce happens in Box2D 2.4.1 (b2_world.cpp / b2_island.cpp /
// b2_contact_solver.cpp): Step() first updates contacts (a contact touches when
// the shapes overlap, skin included), then integrates gravity, solves velocity
// constraints (restitution: the normal velocity after the solve is
// -restitution x the normal velocity measured before it, if that was below
// -restitutionThreshold), integrates positions and pushes penetration deeper
// than b2_linearSlop back out (position only). With continuous physics a ball
// that would sink more than 3 b2_linearSlop into a static wall during the step
// is moved back to its time of impact and the rest of the step is solved from
// there (restitution included): the bounce lands inside the step, not at the
// next one.
#include "engines/box2d/box2d_adapter.h"

#include "engines/engine.h"

#include <box2d/box2d.h>
#include <fmt/format.h>

#ifndef BOUNCECHECK_BOX2D_VERSION
#define BOUNCECHECK_BOX2D_VERSION "unknown"
#endif

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

namespace bouncecheck {
namespace box2d {
namespace {

// Fixture user data: 0 is the ball, 1 + axis a wall whose normal is `axis`.
constexpr std::uintptr_t kBall = 0;

class ContactHook : public b2ContactListener {
public:
    ContactHook(b2Body* ball, float friction, float restitution, float threshold, bool override_mix,
                bool per_contact, float beta)
        : ball_(ball),
          friction_(friction),
          restitution_(restitution),
          threshold_(threshold),
          override_mix_(override_mix),
          per_contact_(per_contact),
          beta_(beta) {}

    // Called from b2Contact::Update when the ball starts touching a wall: in
    // the contact update at the start of Step() (before gravity is integrated
    // and before the solver), or at a time of impact inside Step() (before the
    // time-of-impact solve). Either way the velocity set here is the one the
    // solver starts from, so beta applies once per contact, before the bounce.
    void BeginContact(b2Contact* contact) override {
        if (!per_contact_) return;
        const int axis = wall_axis(contact);
        if (axis < 0) return;
        b2Vec2 v = ball_->GetLinearVelocity();
        // Only if the law counts it (moves_into_wall).
        b2WorldManifold wm;
        contact->GetWorldManifold(&wm);
        // wm.normal points from fixture A to fixture B; make it wall -> ball.
        const bool ball_is_a = contact->GetFixtureA()->GetUserData().pointer == kBall;
        const float n = ball_is_a ? -wm.normal(axis) : wm.normal(axis);
        const float vn = axis == 0 ? v.x : v.y;
        const b2Vec2 g = ball_->GetWorld()->GetGravity();
        if (!moves_into_wall(vn, axis == 0 ? g.x : g.y, n > 0 ? -1 : +1)) return;
        if (axis == 0)
            v.y *= beta_;
        else
            v.x *= beta_;
// GCC 12+ flags b2Body::SetLinearVelocity's by-reference copy of a local as
// a dangling pointer (false positive: it copies the value).
#if defined(__GNUC__) && !defined(__clang__) && __GNUC__ >= 12
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wdangling-pointer"
#endif
        ball_->SetLinearVelocity(v);
#if defined(__GNUC__) && !defined(__clang__) && __GNUC__ >= 12
#pragma GCC diagnostic pop
#endif
    }

    // Every step of a touching contact, before it is solved: set the exact
    // coefficients (b2MixFriction is sqrt(f1 f2), b2MixRestitution max(r1, r2)).
    void PreSolve(b2Contact* contact, const b2Manifold*) override {
        if (!override_mix_) return;
        contact->SetFriction(friction_);
        contact->SetRestitution(restitution_);
        contact->SetRestitutionThreshold(threshold_);
    }

private:
    static int wall_axis(b2Contact* c) {
        const std::uintptr_t a = c->GetFixtureA()->GetUserData().pointer;
        const std::uintptr_t b = c->GetFixtureB()->GetUserData().pointer;
        const std::uintptr_t wall = a != kBall ? a : b;
        return wall == kBall ? -1 : static_cast<int>(wall - 1);
    }

    b2Body* ball_;
    float friction_, restitution_, threshold_;
    bool override_mix_, per_contact_;
    float beta_;
};

class Box2dWorld final : public EngineWorld {
public:
    Box2dWorld(const Scenario& s, const EngineOptions& options, const Tuning& t, const UnitScale& scale,
               std::vector<Setting>& settings)
        : scale_(scale),
          dt_(static_cast<float>(scale.to_engine_time(s.dt))),
          velocity_iterations_(t.velocity_iterations),
          position_iterations_(t.position_iterations) {
        const bool per_contact = options.tangential_model == TangentialModel::per_contact;
        const float mu = per_contact ? 0.0f : static_cast<float>(options.friction);
        const float alpha = static_cast<float>(s.alpha);
        const float wall_friction = t.wall_friction < 0 ? mu : t.wall_friction;
        const float wall_restitution = t.wall_restitution < 0 ? alpha : t.wall_restitution;
        auto L = [&](double x) { return static_cast<float>(scale.to_engine_length(x)); };

        world_ = std::make_unique<b2World>(b2Vec2(static_cast<float>(scale.to_engine_acceleration(s.gravity.x())),
                                                  static_cast<float>(scale.to_engine_acceleration(s.gravity.y()))));
        world_->SetAllowSleeping(t.allow_sleep);
        const bool continuous = options.ccd.value_or(t.continuous);
        world_->SetContinuousPhysics(continuous);
        world_->SetSubStepping(false);
        world_->SetWarmStarting(t.warm_starting);

        // The room: one static body, one box per wall, thick and long enough to
        // cover the corners, its face b2_polygonRadius outside the room so that
        // the skinned surface (face + skin) is the wall.
        b2BodyDef room_def;
        room_def.type = b2_staticBody;
        b2Body* room = world_->CreateBody(&room_def);
        const double size[2] = {scale.to_engine_length(s.room.x()), scale.to_engine_length(s.room.y())};
        const double half_thick = std::max(size[0], size[1]) / 2;
        const double skin = t.compensate_skin ? b2PolygonShape().m_radius : 0.0;  // b2_polygonRadius
        for (const Wall& w : room_walls(s)) {
            b2PolygonShape box;
            const int other = 1 - w.axis;
            const double half_len = size[other] / 2 + 2 * half_thick;
            const double face = scale.to_engine_length(w.offset) + w.side * skin;
            b2Vec2 centre;
            centre(w.axis) = static_cast<float>(face + w.side * half_thick);
            centre(other) = static_cast<float>(size[other] / 2);
            const float hx = static_cast<float>(w.axis == 0 ? half_thick : half_len);
            const float hy = static_cast<float>(w.axis == 0 ? half_len : half_thick);
            box.SetAsBox(hx, hy, centre, 0.0f);
            b2FixtureDef fd;
            fd.shape = &box;
            fd.friction = wall_friction;
            fd.restitution = wall_restitution;
            fd.restitutionThreshold = t.restitution_threshold;
            fd.userData.pointer = 1 + static_cast<std::uintptr_t>(w.axis);
            room->CreateFixture(&fd);
        }

        b2BodyDef ball_def;
        ball_def.type = b2_dynamicBody;
        ball_def.position.Set(L(s.position.x()), L(s.position.y()));
        ball_def.linearVelocity.Set(static_cast<float>(scale.to_engine_velocity(s.velocity.x())),
                                    static_cast<float>(scale.to_engine_velocity(s.velocity.y())));
        ball_def.allowSleep = t.allow_sleep;
        ball_def.awake = true;
        ball_def.fixedRotation = !options.free_rotation;
        ball_def.bullet = false;
        ball_def.linearDamping = 0.0f;
        ball_def.angularDamping = 0.0f;
        ball_def.gravityScale = 1.0f;
        ball_ = world_->CreateBody(&ball_def);
        b2CircleShape circle;
        circle.m_p.SetZero();
        circle.m_radius = L(s.radius);
        b2FixtureDef bd;
        bd.shape = &circle;
        bd.density = 1.0f;
        bd.friction = mu;
        bd.restitution = alpha;
        bd.restitutionThreshold = t.restitution_threshold;
        bd.userData.pointer = kBall;
        ball_->CreateFixture(&bd);

        hook_ = std::make_unique<ContactHook>(ball_, mu, alpha, t.restitution_threshold, t.override_mix, per_contact,
                                              static_cast<float>(s.beta));
        world_->SetContactListener(hook_.get());

        // The largest speed the ball can reach: its energy with the whole
        // room's height to fall (the law never adds energy).
        const double max_move = scale.to_engine_velocity(max_ball_speed(s)) * scale.to_engine_time(s.dt);

        auto set = [&](std::string key, std::string value, std::string why) {
            settings.push_back({std::move(key), std::move(value), std::move(why)});
        };
        set("engine",
            fmt::format("Box2D {} (b2_version says {}.{}.{})", BOUNCECHECK_BOX2D_VERSION, b2_version.major,
                        b2_version.minor, b2_version.revision),
            "Debian libbox2d-dev (version from its CMake package; the 2.4.1 library's b2_version still says "
            "2.4.0); 2D only: a 3D scenario is skipped");
        set("precision", "float",
            "b2Vec2 is float: positions and velocities carry ~7 significant digits and are read back as "
            "float converted to double");
        set("length_scale", fmt::format("{} (ball radius {} m in the engine)", scale.length, L(s.radius)),
            "b2_linearSlop (5 mm), b2_polygonRadius (1 cm) and the TOI target (3 slop) are compile-time "
            "lengths tuned for metre-sized bodies; at scale 1 they are 10-30% of the 5 cm ball. Lengths, "
            "speeds and gravity scale together (the law is scale-free); time is not scaled");
        set("time_scale", fmt::format("{}", scale.time), "one Step(dt) per engine step, dt unchanged");
        set("dt_engine", fmt::format("{} (float)", dt_), "b2World::Step called once per engine step (see substeps)");
        set("restitution", fmt::format("ball {} walls {}", alpha, wall_restitution),
            "effective restitution must be alpha; b2MixRestitution is max(ball, wall)");
        set("friction", fmt::format("ball {} walls {}", mu, wall_friction),
            per_contact ? "tangential_model per-contact: mu = 0, beta applied by the contact hook"
                        : "tangential_model friction: Coulomb mu = options.friction; b2MixFriction is "
                          "sqrt(ball x wall), so both get mu");
        set("combine_override",
            t.override_mix ? fmt::format("PreSolve sets friction {}, restitution {}, threshold {} on every contact",
                                         mu, alpha, t.restitution_threshold)
                           : "off (b2MixFriction / b2MixRestitution / b2MixRestitutionThreshold of fixture values)",
            "exact coefficients whatever the mixing rules round to");
        set("restitution_threshold", fmt::format("{} m/s (engine)", t.restitution_threshold),
            "Box2D default 1 m/s: slower impacts do not bounce at all (at scale 1 the seed's 0.42 m/s "
            "floor impact stops dead). 0: every approaching contact bounces, as in the law");
        set("tangential_model", per_contact ? "per-contact" : "friction",
            per_contact ? "BeginContact (contact update at the start of Step or at a time of impact, before "
                          "the solve) scales the ball's velocity along the wall by beta once, if the ball "
                          "moves into the wall; not again while the contact lasts. Known deviation: a ball "
                          "resting or sliding on a wall micro-hops (each step's gravity re-bounces at threshold 0), "
                          "its contact ends and begins again, and beta damps a slide the law leaves alone"
                        : "Coulomb friction in the contact solver");
        set("free_rotation", options.free_rotation ? "true" : "false (b2BodyDef::fixedRotation)",
            "rotation takes part in friction (rolling) when free");
        set("wall_skin", fmt::format("b2_polygonRadius {} m (engine), faces placed {:.6g} m outside the room",
                                     b2_polygonRadius, skin),
            "polygons collide with a skin of b2_polygonRadius: the effective wall is face + skin");
        set("linear_slop",
            fmt::format("{} m engine = {:.6g} scenario", b2_linearSlop, scale.from_engine_length(b2_linearSlop)),
            "compile-time: the position solver leaves this much penetration; resting ball sits this deep");
        set("baumgarte", fmt::format("{} (TOI {})", b2_baumgarte, b2_toiBaumgarte),
            "compile-time position-correction fractions (position only: adds no velocity)");
        set("sleeping", t.allow_sleep ? "on" : "off (world and body)",
            "Box2D default on: a body slower than b2_linearSleepTolerance for b2_timeToSleep (0.5 s) freezes "
            "while the law still micro-bounces");
        set("ccd", continuous ? "on (TOI against static walls; bullet flag off, sub-stepping off)" : "off",
            options.ccd ? "scenario [engines.box2d] ccd"
                        : "the bounce is resolved at the time of impact inside the step instead of one step late, "
                          "penetration limited to ~3 b2_linearSlop");
        set("velocity_iterations", fmt::format("{}", velocity_iterations_),
            "friction is capped by the normal impulse of the previous iteration: 1 iteration means no "
            "friction at a new contact; one contact converges in 2-3, 8 is ample");
        set("position_iterations", fmt::format("{} (TOI solve: 20, fixed)", position_iterations_),
            "penetration correction; early exit when within slop");
        set("warm_starting", t.warm_starting ? "on" : "off",
            "Box2D default; one contact point: the clamped normal solve is exact either way");
        set("damping", "linear 0, angular 0", "no drag in the law");
        set("max_translation",
            fmt::format("b2_maxTranslation {} m/step; largest expected {:.3g} m/step", b2_maxTranslation, max_move),
            max_move < b2_maxTranslation ? "below the cap: velocity never clamped"
                                         : "ABOVE the cap: Box2D will clamp the ball's speed");
        set("mass", "density 1", "mass cancels out against static walls");
    }

    void step() override { world_->Step(dt_, velocity_iterations_, position_iterations_); }

    void read(State& out) const override {
        const b2Vec2 p = ball_->GetPosition();
        const b2Vec2 v = ball_->GetLinearVelocity();
        out.p = Vec3(scale_.from_engine_length(p.x), scale_.from_engine_length(p.y), 0.0);
        out.v = Vec3(scale_.from_engine_velocity(v.x), scale_.from_engine_velocity(v.y), 0.0);
    }

private:
    UnitScale scale_;
    float dt_;
    int velocity_iterations_, position_iterations_;
    std::unique_ptr<b2World> world_;
    std::unique_ptr<ContactHook> hook_;
    b2Body* ball_ = nullptr;
};

}  // namespace

std::unique_ptr<EngineWorld> build_world(const Scenario& s, const EngineOptions& options, const Tuning& tuning,
                                         std::vector<Setting>& settings) {
    UnitScale scale;
    scale.length = tuning.length_scale > 0 ? tuning.length_scale : 1.0 / s.radius;
    return std::make_unique<Box2dWorld>(s, options, tuning, scale, settings);
}

std::unique_ptr<const Simulator> make_simulator(const Tuning& tuning) {
    EngineCapabilities caps;
    caps.runs_3d = false;
    caps.precision = "float";
    // Box2D 2.4 counts GJK and TOI calls in unsynchronised globals
    // (b2_gjkCalls, b2_toiCalls): one world at a time per process, as every
    // pair runs in a worker process of its own (platform/parallel_pairs.h).
    return make_engine_simulator(
        {kIdentity, caps,
         [tuning](const Scenario& s, const EngineOptions& options, std::vector<Setting>& settings)
             -> std::unique_ptr<EngineWorld> { return build_world(s, options, tuning, settings); }});
}

}  // namespace box2d

std::unique_ptr<const Simulator> make_box2d_simulator() { return box2d::make_simulator(box2d::Tuning{}); }

}  // namespace bouncecheck

// The entry the registry looks up when it loads this adapter's module
// (registry/engine_module.h).
extern "C" const bouncecheck::Simulator* bouncecheck_engine_box2d() {
    return bouncecheck::make_box2d_simulator().release();
}
