// The Siconos 4.4 model of the ball (compiled as C++17: see siconos_model.h).
//
// The ball is a LagrangianLinearTIDS: q = (translation, rotation if any),
// mass matrix diag(m, ..., 2/5 m r^2, ...), constant external force m g.
// Each wall is a LagrangianLinearTIR y = C q + e whose first row is the gap
// (ball surface to wall), with a NewtonImpactNSL(alpha): y_dot+ = -alpha
// y_dot- at an impact, by construction. With friction, two (2D) or three
// (3D) rows (gap, then the contact point's slip along the wall's other axes,
// the rotation included) and a NewtonImpactFrictionNSL(alpha, 0, mu).
#include "engines/siconos/siconos_model.h"

#include <SiconosKernel.hpp>
#include <LsodarOSI.hpp>
#include <SolverOptions.h>
#include <SiconosException.hpp>

#include <cmath>
#include <mutex>
#include <stdexcept>
#include <string>

namespace bouncecheck::siconos_model {
namespace {

// TimeStepping's default reaction to a failed nonsmooth solve prints two
// lines to stdout and goes on with whatever the solver left.
void throw_on_solver_failure(int info, Simulation*) {
    if (info != 0)
        throw std::runtime_error("Siconos nonsmooth solver failed (numerics info = " + std::to_string(info) + ")");
}

// Siconos throws Siconos::exception, whose what() is "std::exception": its
// message is in boost's diagnostic information. Rethrown as a runtime_error
// with it, on one line.
template <class F>
auto guarded(F&& f) -> decltype(f()) {
    try {
        return f();
    } catch (const Siconos::exception& e) {
        std::string why = boost::diagnostic_information(e);
        for (char& c : why)
            if (c == '\n') c = ' ';
        throw std::runtime_error("Siconos: " + why);
    }
}

}  // namespace

struct Model::Impl {
    ModelSpec spec;
    int dofs = 0;
    SP::LagrangianLinearTIDS ball;
    SP::NonSmoothDynamicalSystem nsds;
    std::vector<SP::Interaction> walls;
    SP::TimeStepping ts;
    SP::EventDriven ed;
    SP::Simulation sim;
    SP::MoreauJeanOSI moreau;
    SP::LsodarOSI lsodar;
    std::vector<SP::OneStepNSProblem> problems;

    void configure(OneStepNSProblem& p) const {
        if (!spec.set_solver_options) return;
        SolverOptions& o = *p.numericsSolverOptions();
        o.dparam[SICONOS_DPARAM_TOL] = spec.solver_tolerance;
        o.iparam[SICONOS_IPARAM_MAX_ITER] = spec.solver_max_iterations;
    }

    bool in_index_set(unsigned level, const SP::Interaction& inter) const {
        SP::Topology topo = nsds->topology();
        if (topo->indexSetsSize() <= level) return false;
        SP::InteractionsGraph set = topo->indexSet(level);
        return set && set->is_vertex(inter);
    }
};

Model::Model(const ModelSpec& spec) : impl_(std::make_unique<Impl>()) {
    guarded([&] { build(spec); });
}

void Model::build(const ModelSpec& spec) {
    Impl& m = *impl_;
    m.spec = spec;
    const int dim = spec.dim;
    const int rot = spec.rotation ? (dim == 3 ? 3 : 1) : 0;
    const int n = dim + rot;
    m.dofs = n;

    SP::SiconosVector q0(new SiconosVector(n)), v0(new SiconosVector(n)), weight(new SiconosVector(n));
    q0->zero();
    v0->zero();
    weight->zero();
    SP::SimpleMatrix mass(new SimpleMatrix(n, n));
    mass->zero();
    const double inertia = 0.4 * spec.mass * spec.radius * spec.radius;  // a solid sphere
    for (int i = 0; i < n; ++i) (*mass)(i, i) = i < dim ? spec.mass : inertia;
    for (int i = 0; i < dim; ++i) {
        (*q0)(i) = spec.position[i];
        (*v0)(i) = spec.velocity[i];
        (*weight)(i) = spec.mass * spec.gravity[i];
    }
    m.ball.reset(new LagrangianLinearTIDS(q0, v0, mass));
    m.ball->setFExtPtr(weight);

    m.nsds.reset(new NonSmoothDynamicalSystem(0.0, spec.final_time));
    m.nsds->insertDynamicalSystem(m.ball);

    const bool friction = spec.friction > 0;
    if (friction && spec.scheme == Scheme::event_driven)
        throw std::invalid_argument("LsodarOSI has no friction (NewtonImpactFrictionNSL is not implemented for it)");
    const unsigned rows = friction ? static_cast<unsigned>(dim) : 1u;
    for (const WallSpec& w : spec.walls) {
        // Gap: (-side) (q_axis - offset) - r.
        SP::SimpleMatrix C(new SimpleMatrix(rows, n));
        C->zero();
        SP::SiconosVector e(new SiconosVector(rows));
        e->zero();
        (*C)(0, w.axis) = -w.side;
        (*e)(0) = w.side * w.offset - spec.radius;
        if (friction) {
            // Slip of the contact point d = side r e_axis along each other
            // axis t: t.(v + omega x d) = t.v + omega.(d x t).
            unsigned row = 1;
            for (int a = 0; a < dim; ++a) {
                if (a == w.axis) continue;
                (*C)(row, a) = 1.0;
                if (rot) {
                    double d[3] = {0, 0, 0}, t[3] = {0, 0, 0};
                    d[w.axis] = w.side * spec.radius;
                    t[a] = 1.0;
                    const double cross[3] = {d[1] * t[2] - d[2] * t[1], d[2] * t[0] - d[0] * t[2],
                                             d[0] * t[1] - d[1] * t[0]};
                    if (dim == 3)
                        for (int k = 0; k < 3; ++k) (*C)(row, dim + k) = cross[k];
                    else
                        (*C)(row, dim) = cross[2];  // 2D: rotation about the out-of-plane axis
                }
                ++row;
            }
        }
        SP::NonSmoothLaw law;
        if (friction) law.reset(new NewtonImpactFrictionNSL(spec.restitution, 0.0, spec.friction, rows));
        else law.reset(new NewtonImpactNSL(spec.restitution));
        SP::Relation relation(new LagrangianLinearTIR(C, e));
        SP::Interaction inter(new Interaction(law, relation));
        m.nsds->link(inter, m.ball);
        m.walls.push_back(inter);
    }

    SP::TimeDiscretisation td(new TimeDiscretisation(0.0, spec.dt));
    if (spec.scheme == Scheme::moreau_jean) {
        m.moreau.reset(new MoreauJeanOSI(spec.theta, spec.gamma));
        m.moreau->setConstraintActivationThreshold(spec.activation_threshold);
        m.moreau->setUseGammaForRelation(spec.use_gamma_for_relation);
        SP::OneStepNSProblem problem;
        const int solver = spec.lcp_solver ? spec.lcp_solver : SICONOS_LCP_LEMKE;
        if (friction) problem.reset(new FrictionContact(dim));
        else problem.reset(new LCP(solver));
        m.configure(*problem);
        m.problems.push_back(problem);
        m.ts.reset(new TimeStepping(m.nsds, td, m.moreau, problem));
        // Kept in a file-static pointer (TimeStepping.cpp): every world writes the same one.
        m.ts->setCheckSolverFunction(&throw_on_solver_failure);
        m.ts->associate(m.moreau, m.ball);
        m.sim = m.ts;
    } else {
        m.lsodar.reset(new LsodarOSI());
        // LsodarOSI::setTol(itol, rtol, atol) with scalars writes rtol into
        // atol (LsodarOSI.cpp, 4.4.0): write the arrays it integrates with.
        if (spec.lsodar_rtol > 0) m.lsodar->getRtol()[0] = spec.lsodar_rtol;
        if (spec.lsodar_atol > 0) m.lsodar->getAtol()[0] = spec.lsodar_atol;
        SP::OneStepNSProblem impact(new LCP(SICONOS_LCP_LEMKE)), acceleration(new LCP(SICONOS_LCP_LEMKE));
        m.configure(*impact);
        m.configure(*acceleration);
        m.problems = {impact, acceleration};
        m.ed.reset(new EventDriven(m.nsds, td));
        // EventDriven::_TOL_ED is a static: every world sets it, so a value
        // left by another world (a test's) never carries over.
        if (spec.event_tolerance > 0) m.ed->setToleranceED(spec.event_tolerance);
        m.ed->associate(m.lsodar, m.ball);
        m.ed->insertNonSmoothProblem(impact, SICONOS_OSNSP_ED_IMPACT);
        m.ed->insertNonSmoothProblem(acceleration, SICONOS_OSNSP_ED_SMOOTH_ACC);
        m.sim = m.ed;
    }
    m.sim->initialize();

    Effective& e = effective_;
    e.dofs = n;
    e.version = std::string("Siconos 4.4 (") + BOUNCECHECK_SICONOS_KERNEL_FILE + ")";
    if (m.moreau) {
        e.theta = m.moreau->theta();
        e.gamma = m.moreau->gamma();
        e.use_gamma = m.moreau->useGamma();
        e.use_gamma_for_relation = m.moreau->useGammaForRelation();
        e.activation_threshold = m.moreau->constraintActivationThreshold();
    }
    const SolverOptions& o = *m.problems.front()->numericsSolverOptions();
    e.solver_id = o.solverId;
    e.solver = solver_options_id_to_name(o.solverId);
    e.solver_tolerance = o.dparam[SICONOS_DPARAM_TOL];
    e.solver_max_iterations = o.iparam[SICONOS_IPARAM_MAX_ITER];
    if (m.lsodar) {
        e.lsodar_rtol = m.lsodar->getRtol()[0];
        e.lsodar_atol = m.lsodar->getAtol()[0];
        e.event_tolerance = m.ed->toleranceED();
    }
    e.tick = m.sim->eventsManager()->currentEvent()->getTick();
    e.gap_limit_ticks = m.sim->eventsManager()->getGapLimitEvents();
}

// Siconos 4.4's integrators and nonsmooth problems hold a shared_ptr to their
// Simulation, which holds them in maps; Simulation::clear() (meant for the
// Model class 4.4 no longer has) breaks that cycle. The rest of the object
// graph still leaks inside the library (scripts/lsan-suppressions.txt).
Model::~Model() {
    if (impl_ && impl_->sim) impl_->sim->clear();
}

void Model::compute_step() {
    guarded([&] { impl_->ts->computeOneStep(); });
    ++counters_.solver_calls;
}

void Model::finish_step() {
    guarded([&] { impl_->ts->nextStep(); });
}

bool Model::advance_to_event() {
    if (!impl_->ed->hasNextEvent()) throw std::runtime_error("Siconos EventDriven: no event left before the run's end");
    guarded([&] { impl_->ed->advanceToEvent(); });
    const bool root = impl_->ed->istate() == 3;
    if (root) ++counters_.roots;
    return root;
}

void Model::process_events() {
    guarded([&] { impl_->ed->processEvents(); });
    ++counters_.events;
}

double Model::current_time() const { return impl_->sim->startingTime(); }

bool Model::has_next_event() const { return impl_->sim->hasNextEvent(); }

std::array<double, 3> Model::position() const {
    std::array<double, 3> out{};
    const SiconosVector& q = *impl_->ball->q();
    for (int i = 0; i < impl_->spec.dim; ++i) out[i] = q(i);
    return out;
}

std::array<double, 3> Model::velocity() const {
    std::array<double, 3> out{};
    const SiconosVector& v = *impl_->ball->velocity();
    for (int i = 0; i < impl_->spec.dim; ++i) out[i] = v(i);
    return out;
}

void Model::set_translation(const std::array<double, 3>& position, const std::array<double, 3>& velocity,
                            bool refresh_outputs) {
    SiconosVector& q = *impl_->ball->q();
    SiconosVector& v = *impl_->ball->velocity();
    for (int i = 0; i < impl_->spec.dim; ++i) {
        q(i) = position[i];
        v(i) = velocity[i];
    }
    if (refresh_outputs)
        guarded([&] {
            impl_->nsds->updateOutput(impl_->sim->nextTime(), 0);
            impl_->nsds->updateOutput(impl_->sim->nextTime(), 1);
        });
}

Model::WallStatuses Model::walls() const {
    const Impl& m = *impl_;
    WallStatuses out{};
    for (std::size_t w = 0; w < m.walls.size(); ++w) {
        const SP::Interaction& inter = m.walls[w];
        WallStatus& st = out[w];
        st.gap = inter->y(0)->getValue(0);
        if (m.ts) st.impulse = inter->lambda(1)->getValue(0);
        st.in_impact_set = m.in_index_set(1, inter);
        st.in_resting_set = m.ed && m.in_index_set(2, inter);
    }
    return out;
}

}  // namespace bouncecheck::siconos_model
