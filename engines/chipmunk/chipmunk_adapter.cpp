// Chipmunk2D 7.0.3 (2D only, double precision): the ball is a dynamic circle,
// the room four static segments. Every setting that changes the answer is
// chosen here and reported; see engines/chipmunk/chipmunk_adapter.h for the
// defaults they replace.
//
// How a bounce happens in Chipmunk 7.0.3 (cpSpaceStep.c, cpArbiter.c):
// cpSpaceStep(dt) first moves every body by its velocity from the end of the
// previous step (p += (v + v_bias) dt: explicit Euler's position update, as the
// document's), then finds the overlapping pairs at the new positions (a
// circle and a segment touch when their distance is strictly below the sum
// of their radii) and calls the collision handlers (begin for a new contact,
// then preSolve). cpArbiterPreStep then takes each contact's bounce target,
// e times the normal velocity as it is then: the velocity before this step's
// gravity. Gravity is integrated after that (v += g dt), and the impulse
// solver drives the normal velocity to -e times the pre-gravity one. So the
// outgoing speed is alpha |v_n|, not alpha |v_n + g dt| as in the document.
// Restitution is applied at every step of a contact (no threshold, no
// first-contact rule); a separating contact takes no impulse (the accumulated
// impulse is clamped at zero). Penetration is removed by a separate bias
// velocity (position only, no energy), 1 - collisionBias^dt of the overlap
// beyond collisionSlop per step. There is no continuous collision detection.
#include "engines/chipmunk/chipmunk_adapter.h"

#include "engines/engine.h"

#include <chipmunk/chipmunk.h>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <string>
#include <vector>

#include <fcntl.h>
#include <unistd.h>

static_assert(CP_USE_DOUBLES == 1 && sizeof(cpFloat) == 8,
              "Chipmunk must be used with cpFloat = double (CP_USE_DOUBLES, the library's default and Debian's build)");
static_assert(CP_VERSION_MAJOR == 7, "the adapter is written against Chipmunk 7's API and stepping");

namespace bouncecheck {
namespace chipmunk {
namespace {

// What the library does once per process, checked before any world is built.
struct LibraryCheck {
    bool double_roundtrip = false;  // a double set on a body reads back bit for bit
    std::string banner;             // what cpSpaceInit printed to stdout (a debug build prints two lines)
};

// Debian builds libchipmunk without NDEBUG (its CMake build type is None):
// assertions are on, and the first cpSpaceInit of a process prints two lines
// to stdout, guarded by an unsynchronised `static cpBool done` (cpSpace.c,
// cpSpaceInit) - the library's only global state a step touches. One space
// is created and freed here, once per process under std::call_once, with
// stdout pointed at a temporary file: afterwards `done` is only read, so
// spaces may be created and stepped on several threads, and bouncecheck's
// own stdout is not interleaved with the banner.
const LibraryCheck& library_check() {
    static LibraryCheck check;
    static std::once_flag once;
    std::call_once(once, [] {
        std::fflush(stdout);
        const int saved = ::dup(STDOUT_FILENO);
        std::FILE* capture = std::tmpfile();
        const bool redirected = saved >= 0 && capture && ::dup2(::fileno(capture), STDOUT_FILENO) >= 0;
        cpSpace* space = cpSpaceNew();
        cpBody* body = cpBodyNew(1.0, INFINITY);
        const cpVect probe = cpv(1.0 / 3.0, 0.1);
        cpBodySetPosition(body, probe);
        const cpVect back = cpBodyGetPosition(body);
        check.double_roundtrip = back.x == probe.x && back.y == probe.y && cpBodyGetMass(body) == 1.0;
        cpBodyFree(body);
        cpSpaceFree(space);
        std::fflush(stdout);
        if (redirected) {
            ::dup2(saved, STDOUT_FILENO);
            std::rewind(capture);
            char buf[512];
            while (std::fgets(buf, sizeof buf, capture)) check.banner += buf;
            while (!check.banner.empty() && check.banner.back() == '\n') check.banner.pop_back();
            std::replace(check.banner.begin(), check.banner.end(), '\n', ' ');
        }
        if (saved >= 0) ::close(saved);
        if (capture) std::fclose(capture);
    });
    return check;
}

constexpr cpCollisionType kBallType = 1;
constexpr cpCollisionType kWallType = 2;

// What the per-contact hook needs; a wall shape's user data points at its Wall.
struct HookContext {
    cpBody* ball = nullptr;
    double beta = 1.0;
    cpVect gravity = cpvzero;
};

// Per-contact tangential damping. Called from cpSpaceStep's collision
// detection (cpSpaceCollideShapes), after the position update and before
// cpArbiterPreStep, gravity and the solver: the velocity scaled is the ball's
// velocity at the end of the previous step, the one that carried it into the
// wall. beginFunc runs once when a contact starts (a new arbiter, or one
// cached after at least one step apart); preSolveFunc runs every step the
// shapes overlap.
cpBool scale_tangential(cpArbiter* arb, cpSpace*, cpDataPointer data) {
    const auto* hook = static_cast<const HookContext*>(data);
    CP_ARBITER_GET_SHAPES(arb, ball_shape, wall_shape);
    (void)ball_shape;
    const auto* wall = static_cast<const Wall*>(cpShapeGetUserData(wall_shape));
    cpVect v = cpBodyGetVelocity(hook->ball);
    const double vn = wall->axis == 0 ? v.x : v.y;
    const double gn = wall->axis == 0 ? hook->gravity.x : hook->gravity.y;
    // Only if the law counts it (moves_into_wall): not a ball touching a wall
    // that gravity pulls it away from (seed-2d's ceiling at t = 0).
    if (moves_into_wall(vn, gn, wall->side)) {
        if (wall->axis == 0) v.y *= hook->beta;
        else v.x *= hook->beta;
        cpBodySetVelocity(hook->ball, v);
    }
    return cpTrue;
}

class ChipmunkWorld final : public EngineWorld {
public:
    ChipmunkWorld(const Scenario& s, const EngineOptions& options, const Tuning& t, std::vector<Setting>& settings)
        : dt_(s.dt), walls_(room_walls(s)) {
        const LibraryCheck& lib = library_check();
        if (!lib.double_roundtrip)
            throw std::runtime_error("libchipmunk does not read back a double bit for bit: it is not built with "
                                     "cpFloat = double (CP_USE_DOUBLES), as its headers say");

        const bool per_contact = options.tangential_model == TangentialModel::per_contact;
        const double mu = per_contact ? 0.0 : options.friction;
        const double alpha = s.alpha;

        space_ = cpSpaceNew();
        cpSpaceSetGravity(space_, cpv(s.gravity.x(), s.gravity.y()));
        cpSpaceSetIterations(space_, t.iterations);
        cpSpaceSetCollisionSlop(space_, t.collision_slop);
        cpSpaceSetCollisionBias(space_, t.collision_bias);
        cpSpaceSetCollisionPersistence(space_, t.collision_persistence);
        cpSpaceSetDamping(space_, t.damping);
        cpSpaceSetSleepTimeThreshold(space_, t.sleep_time_threshold);
        cpSpaceSetIdleSpeedThreshold(space_, 0.0);

        // The room: one segment per wall on the space's static body, long
        // enough to run past the corners, its line wall_radius outside the
        // room so that the rounded surface (line + radius) is the wall. A
        // segment pushes a ball out on the side its centre is on: the walls
        // are thick enough that one step cannot carry the centre past the
        // line (twice the largest step the law allows: the ball's speed with
        // the whole room to fall, the law never adds energy), or the ball
        // would be pushed out of the room and lost.
        const double size[2] = {s.room.x(), s.room.y()};
        const double max_step = max_ball_speed(s) * dt_;
        const double radius =
            t.wall_radius > 0 ? t.wall_radius : std::max(std::max(size[0], size[1]) / 2, 2 * max_step);
        const double shift = t.compensate_wall_radius ? radius : 0.0;
        const double overhang = 2 * radius + s.radius;
        cpBody* room = cpSpaceGetStaticBody(space_);
        for (Wall& w : walls_) {
            const int other = 1 - w.axis;
            const double line = w.offset + w.side * shift;
            double a[2], b[2];
            a[w.axis] = b[w.axis] = line;
            a[other] = -overhang;
            b[other] = size[other] + overhang;
            cpShape* seg = cpSegmentShapeNew(room, cpv(a[0], a[1]), cpv(b[0], b[1]), radius);
            cpShapeSetElasticity(seg, t.wall_elasticity);
            cpShapeSetFriction(seg, t.wall_friction);
            cpShapeSetCollisionType(seg, kWallType);
            cpShapeSetUserData(seg, &w);
            cpSpaceAddShape(space_, seg);
            shapes_.push_back(seg);
        }

        const double mass = 1.0;
        const double moment = options.free_rotation ? cpMomentForCircle(mass, 0.0, s.radius, cpvzero) : INFINITY;
        ball_ = cpBodyNew(mass, moment);
        cpBodySetPosition(ball_, cpv(s.position.x(), s.position.y()));
        cpBodySetVelocity(ball_, cpv(s.velocity.x(), s.velocity.y()));
        cpSpaceAddBody(space_, ball_);
        cpShape* circle = cpCircleShapeNew(ball_, s.radius, cpvzero);
        cpShapeSetElasticity(circle, alpha);
        cpShapeSetFriction(circle, mu);
        cpShapeSetCollisionType(circle, kBallType);
        cpSpaceAddShape(space_, circle);
        shapes_.push_back(circle);

        hook_.ball = ball_;
        hook_.beta = s.beta;
        hook_.gravity = cpSpaceGetGravity(space_);
        if (per_contact) {
            cpCollisionHandler* handler = cpSpaceAddCollisionHandler(space_, kBallType, kWallType);
            handler->userData = &hook_;
            if (t.per_contact_callback == PerContactCallback::begin) handler->beginFunc = scale_tangential;
            else handler->preSolveFunc = scale_tangential;
        }

        auto set = [&](std::string key, std::string value, std::string why) {
            settings.push_back({std::move(key), std::move(value), std::move(why)});
        };
        const double bias_per_step = 1.0 - std::pow(t.collision_bias, dt_);
        set("engine", fmt::format("Chipmunk2D {} (cpVersionString)", cpVersionString),
            "Debian libchipmunk-dev; 2D only: a 3D scenario is skipped");
        set("precision", fmt::format("double (sizeof(cpFloat) = {}, CP_USE_DOUBLES)", sizeof(cpFloat)),
            "static_assert on the headers; at run time a double set on a body reads back bit for bit "
            "(a float library would not)");
        set("debug_build",
            lib.banner.empty() ? std::string("no banner from cpSpaceInit (NDEBUG build)")
                               : fmt::format("yes: cpSpaceInit printed \"{}\"", lib.banner),
            "Debian builds without NDEBUG: cpAssertSoft/Warn are on (an insane body aborts the process). The "
            "banner is printed once per process behind an unsynchronised static flag: the adapter takes it once, "
            "under std::call_once with stdout captured, before any world is built");
        set("length_scale", "1 (the space's units are metres)",
            "Chipmunk 7 has no compile-time lengths: its one length default, collisionSlop, is set here, and the "
            "BB tree's margins are relative (10% of a shape, 0.1 s of travel: broad phase only)");
        set("dt_engine", fmt::format("{}", dt_), "cpSpaceStep called once per engine step (see substeps)");
        set("elasticity", fmt::format("ball {} walls {}", alpha, t.wall_elasticity),
            "a contact's e is ball x wall (cpArbiterUpdate): walls 1 make it alpha exactly; no restitution "
            "threshold. Chipmunk's default shape elasticity is 0");
        set("friction", fmt::format("ball {} walls {}", mu, t.wall_friction),
            per_contact ? "tangential_model per-contact: mu = 0, beta applied by the contact hook"
                        : "tangential_model friction: Coulomb mu = options.friction; a contact's u is ball x wall, "
                          "walls 1 make it mu exactly. Chipmunk's default shape friction is 0");
        set("tangential_model", per_contact ? "per-contact" : "friction",
            per_contact
                ? (t.per_contact_callback == PerContactCallback::begin
                       ? "cpCollisionHandler beginFunc (ball, wall): when a contact starts, after the step's "
                         "position update and before its gravity and solve, the ball's velocity along the wall (the "
                         "end-of-previous-step velocity) is scaled by beta once, if the ball moves into the wall "
                         "(moves_into_wall); not again while the shapes overlap. A contact starts again after one "
                         "step apart"
                       : "cpCollisionHandler preSolveFunc: beta at every step the shapes overlap (not the adapter's "
                         "choice)")
                : "Coulomb friction in the impulse solver");
        set("free_rotation", options.free_rotation ? "true" : "false (moment INFINITY)",
            "rotation takes part in friction (rolling) when free");
        set("bounce_velocity", "restitution applies to the velocity before the step's gravity",
            "cpArbiterPreStep takes bounce = e x normal velocity before cpBodyUpdateVelocity adds g dt; the solver "
            "then cancels that step's gravity in the normal direction. Outgoing speed alpha |v| for the velocity "
            "v at the end of the previous step: the measured alpha (incoming = previous sample + g dt) reads "
            "alpha (1 - |g| dt / v_in) at the floor, alpha at a side wall, and above alpha at the ceiling (gravity "
            "pulls away: the ball leaves faster than the law's alpha (|v| - |g| dt))");
        set("walls",
            fmt::format("static segments, radius {:.6g} m, lines {:.6g} m outside the room (largest step the law "
                        "allows: {:.3g} m)",
                        radius, shift, max_step),
            "a segment collides as a capsule: line + radius is the wall. Thick walls (half the room's larger side, "
            "at least two of the largest steps): a ball is pushed back into the room unless its centre passes the "
            "segment's line, which one step cannot do");
        set("collision_slop", fmt::format("{} m", t.collision_slop),
            "overlap the bias never pushes out. Chipmunk default 0.1 (in the space's units, two radii of the seed's "
            "ball): a ball stays as deep as a step carried it (a dead ball landing at 1 m/s at dt 0.03: 3 cm, for "
            "good)");
        set("collision_bias",
            fmt::format("{:.6g} ({:.6g} of the overlap pushed out per step of {} s)", t.collision_bias, bias_per_step,
                        dt_),
            "Chipmunk's default (10% per 1/60 s), kept: position-only correction (bias velocity, reset after the "
            "position update), no energy. A bounced ball mostly leaves before its overlap is removed. Full correction "
            "(0) is the document's clamp a step late, but a resting ball then hops every few steps, each hop a new "
            "contact: per-contact beta stops a slide the law keeps (0.1 -> 0.019 m/s in 5 s at dt 0.01)");
        set("iterations", fmt::format("{}", t.iterations),
            "Chipmunk's default; one contact converges in one iteration (friction is bounded by the same "
            "iteration's normal impulse), a corner's two in a few");
        set("collision_persistence", fmt::format("{} steps", t.collision_persistence),
            "Chipmunk's default: an arbiter and its accumulated impulse are kept this many steps after the shapes "
            "separate; a contact that resumes within them starts from that impulse");
        set("sleeping",
            std::isinf(t.sleep_time_threshold) ? std::string("off (sleepTimeThreshold INFINITY)")
                                               : fmt::format("on after {} s idle", t.sleep_time_threshold),
            "Chipmunk's default is off; set explicitly: a sleeping ball would freeze while the law micro-bounces");
        set("damping", fmt::format("{}", t.damping), "velocity kept per second (Chipmunk default 1: none); no drag in the law");
        set("ccd", "none (Chipmunk 7 has no continuous collision detection)",
            "the narrow phase tests the positions at the end of the position update only; substeps are the remedy "
            "against fast balls and large dt");
        set("mass", "1", "mass cancels out against static walls");
    }

    ~ChipmunkWorld() override {
        // The space first (it touches its bodies while it is destroyed), then
        // what was added to it.
        cpSpaceFree(space_);
        for (cpShape* shape : shapes_) cpShapeFree(shape);
        cpBodyFree(ball_);
    }

    ChipmunkWorld(const ChipmunkWorld&) = delete;
    ChipmunkWorld& operator=(const ChipmunkWorld&) = delete;

    void step() override { cpSpaceStep(space_, dt_); }

    void read(State& out) const override {
        const cpVect p = cpBodyGetPosition(ball_);
        const cpVect v = cpBodyGetVelocity(ball_);
        out.p = Vec3(p.x, p.y, 0.0);
        out.v = Vec3(v.x, v.y, 0.0);
    }

private:
    double dt_;
    std::vector<Wall> walls_;  // the wall shapes' user data: never resized after they are made
    cpSpace* space_ = nullptr;
    cpBody* ball_ = nullptr;
    std::vector<cpShape*> shapes_;
    HookContext hook_;
};

}  // namespace

std::unique_ptr<EngineWorld> build_world(const Scenario& s, const EngineOptions& options, const Tuning& tuning,
                                         std::vector<Setting>& settings) {
    return std::make_unique<ChipmunkWorld>(s, options, tuning, settings);
}

std::unique_ptr<const Simulator> make_simulator(const Tuning& tuning) {
    // The once-per-process library check now, on the thread that builds the
    // simulators, so that no two worlds race for cpSpaceInit's static flag.
    library_check();
    EngineCapabilities caps;
    caps.runs_3d = false;
    caps.precision = "double";
    // After library_check() no global state of Chipmunk 7.0.3 is written by
    // creating or stepping a space (cpSpaceInit's banner flag is the only
    // writable static in the library; shape ids and every buffer are per space).
    return make_engine_simulator(
        {kIdentity, caps,
         [tuning](const Scenario& s, const EngineOptions& options, std::vector<Setting>& settings)
             -> std::unique_ptr<EngineWorld> { return build_world(s, options, tuning, settings); }});
}

}  // namespace chipmunk

std::unique_ptr<const Simulator> make_chipmunk_simulator() { return chipmunk::make_simulator(chipmunk::Tuning{}); }

}  // namespace bouncecheck

// The entry the registry looks up when it loads this adapter's module
// (registry/engine_module.h).
extern "C" const bouncecheck::Simulator* bouncecheck_engine_chipmunk() {
    return bouncecheck::make_chipmunk_simulator().release();
}
