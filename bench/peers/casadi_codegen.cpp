// CasADi C code of Pinocchio's algorithms on casadi::SX, for the chain of bench/native.py's input
// file, in two forms:
//   pin_<op>:  the design's constants baked in (inputs: the state only);
//   pind_<op>: the design as inputs, as apair's kernels take it (dh (4n), links (10n), gravity (3)).
// Operations: fk (T, row-major 4x4), jacobian (6 x n, LOCAL_WORLD_ALIGNED, row-major), mass_matrix
// (n x n, both triangles), inverse_dynamics (rnea), forward_dynamics (aba), and the derivatives
// of the dynamics by CasADi's own differentiation of those SX graphs (ADScalar::jacobian):
// inverse_dynamics_derivatives (two outputs: d rnea / dq, d rnea / dv) and
// forward_dynamics_derivatives (three: d aba / dq, d aba / dv, d aba / dtau = Minv, the last as
// apair's kernel and Pinocchio's computeABADerivatives give it too). Outputs are column vectors in
// row-major order. Usage: casadi_codegen INPUT OUTPUT_DIR
#include <pinocchio/autodiff/casadi.hpp>

#include <pinocchio/algorithm/aba.hpp>
#include <pinocchio/algorithm/crba.hpp>
#include <pinocchio/algorithm/frames.hpp>
#include <pinocchio/algorithm/jacobian.hpp>
#include <pinocchio/algorithm/kinematics.hpp>
#include <pinocchio/algorithm/rnea.hpp>
#include <pinocchio/multibody.hpp>

#include <string>
#include <vector>

#include "bench_inputs.h"

using namespace pinocchio;
typedef ::casadi::SX ADScalar;
typedef ModelTpl<ADScalar> ADModel;
typedef DataTpl<ADScalar> ADData;
typedef Eigen::Matrix<ADScalar, Eigen::Dynamic, 1> ADVector;
typedef Eigen::Matrix<ADScalar, 3, 3> ADMatrix3;
typedef Eigen::Matrix<ADScalar, 3, 1> ADVector3;
typedef SE3Tpl<ADScalar> ADSE3;

// Rz(phi) Tz(c) Tx(a) Rx(alpha) in scalar S
template <typename S>
static SE3Tpl<S> dh_placement(const S &a, const S &alpha, const S &c, const S &phi)
{
    typedef Eigen::Matrix<S, 3, 3> M3;
    typedef Eigen::Matrix<S, 3, 1> V3;
    M3 Rz, Rx;
    Rz << cos(phi), -sin(phi), S(0), sin(phi), cos(phi), S(0), S(0), S(0), S(1);
    Rx << S(1), S(0), S(0), S(0), cos(alpha), -sin(alpha), S(0), sin(alpha), cos(alpha);
    V3 p;
    p << a * cos(phi), a * sin(phi), c;
    return SE3Tpl<S>(Rz * Rx, p);
}

template <typename S>
static InertiaTpl<S> link_inertia(const S *L)
{
    Eigen::Matrix<S, 3, 3> I;
    I << L[4], L[7], L[8], L[7], L[5], L[9], L[8], L[9], L[6];
    return InertiaTpl<S>(L[0], Eigen::Matrix<S, 3, 1>(L[1], L[2], L[3]), I);
}

// The chain in scalar S from its design values (numbers or symbols), as bench/run.py's pin_model.
template <typename S>
static ModelTpl<S> build(const S *dh, const S *links, const S *grav)
{
    ModelTpl<S> model;
    JointIndex parent = 0;
    SE3Tpl<S> placement = SE3Tpl<S>::Identity();
    for (int i = 0; i < N; ++i) {
        parent = model.addJoint(parent, typename ModelTpl<S>::JointModel(JointModelRevoluteTpl<S, 0, 2>()), placement,
                                "r" + std::to_string(i));
        SE3Tpl<S> D = dh_placement<S>(dh[4 * i], dh[4 * i + 1], dh[4 * i + 2], dh[4 * i + 3]);
        model.appendBodyToJoint(parent, D.act(link_inertia<S>(links + 10 * i)), SE3Tpl<S>::Identity());
        placement = D;
    }
    model.addFrame(FrameTpl<S>("end", parent, 0, placement, OP_FRAME));
    model.gravity = MotionTpl<S>(Eigen::Matrix<S, 3, 1>(grav[0], grav[1], grav[2]), Eigen::Matrix<S, 3, 1>::Zero());
    return model;
}

static std::vector<std::pair<std::string, long long>> COUNTS;  // SX operations per function

static void add(::casadi::CodeGenerator &gen, const ::casadi::Function &f)
{
    gen.add(f);
    long long ops = 0;  // instructions that are operations (not inputs, outputs or constants)
    for (casadi_int k = 0; k < f.n_instructions(); ++k) {
        const casadi_int op = f.instruction_id(k);
        if (op != ::casadi::OP_INPUT && op != ::casadi::OP_OUTPUT && op != ::casadi::OP_CONST) ++ops;
    }
    COUNTS.emplace_back(f.name(), ops);
}

static ADScalar column(const std::vector<ADScalar> &entries)
{
    return ADScalar::vertcat(entries);
}

// the entries of the SX matrix A as a dense column, row by row (a jacobian's structural zeros
// written as zeros: a sparse output would be written compressed)
static ADScalar row_major(const ADScalar &A)
{
    const ADScalar D = ADScalar::densify(A);
    std::vector<ADScalar> entries;
    for (casadi_int r = 0; r < D.size1(); ++r)
        for (casadi_int c = 0; c < D.size2(); ++c) entries.push_back(D(r, c));
    return ADScalar::densify(column(entries));
}

static void add_functions(::casadi::CodeGenerator &gen, ADModel &model, const std::string &prefix,
                          const std::vector<ADScalar> &design)
{
    ADData data(model);
    const FrameIndex fid = model.getFrameId("end");
    ADScalar q = ADScalar::sym("q", N), v = ADScalar::sym("v", N), a = ADScalar::sym("a", N);
    ADVector qe(N), ve(N), ae(N);
    for (int i = 0; i < N; ++i) {
        qe[i] = q(i);
        ve[i] = v(i);
        ae[i] = a(i);
    }
    auto inputs = [&](std::vector<ADScalar> state, int design_count) {
        for (int k = 0; k < design_count; ++k) state.push_back(design[k]);
        return state;
    };
    const int with_dh = design.empty() ? 0 : 1, with_links = design.empty() ? 0 : 2, all = design.empty() ? 0 : 3;
    std::vector<ADScalar> out;
    // forward kinematics
    forwardKinematics(model, data, qe);
    updateFramePlacement(model, data, fid);
    {
        Eigen::Matrix<ADScalar, 4, 4> H = data.oMf[fid].toHomogeneousMatrix();
        out.clear();
        for (int r = 0; r < 4; ++r)
            for (int c = 0; c < 4; ++c) out.push_back(H(r, c));
        add(gen, ::casadi::Function(prefix + "fk", inputs({q}, with_dh), {column(out)}));
    }
    {
        typename ADData::Matrix6x J(6, N);
        J.setZero();
        computeFrameJacobian(model, data, qe, fid, LOCAL_WORLD_ALIGNED, J);
        out.clear();
        for (int r = 0; r < 6; ++r)
            for (int c = 0; c < N; ++c) out.push_back(J(r, c));
        add(gen, ::casadi::Function(prefix + "jacobian", inputs({q}, with_dh), {column(out)}));
    }
    {
        crba(model, data, qe);
        out.clear();
        for (int r = 0; r < N; ++r)
            for (int c = 0; c < N; ++c) out.push_back(r <= c ? data.M(r, c) : data.M(c, r));
        add(gen, ::casadi::Function(prefix + "mass_matrix", inputs({q}, with_links), {column(out)}));
    }
    {
        rnea(model, data, qe, ve, ae);
        out.clear();
        for (int r = 0; r < N; ++r) out.push_back(data.tau[r]);
        add(gen, ::casadi::Function(prefix + "inverse_dynamics", inputs({q, v, a}, all), {column(out)}));
        const ADScalar tau = column(out);
        add(gen, ::casadi::Function(prefix + "inverse_dynamics_derivatives", inputs({q, v, a}, all),
                                    {row_major(ADScalar::jacobian(tau, q)), row_major(ADScalar::jacobian(tau, v))}));
    }
    {
        aba(model, data, qe, ve, ae);  // a is the torque here
        out.clear();
        for (int r = 0; r < N; ++r) out.push_back(data.ddq[r]);
        add(gen, ::casadi::Function(prefix + "forward_dynamics", inputs({q, v, a}, all), {column(out)}));
        const ADScalar ddq = column(out);
        add(gen, ::casadi::Function(prefix + "forward_dynamics_derivatives", inputs({q, v, a}, all),
                                    {row_major(ADScalar::jacobian(ddq, q)), row_major(ADScalar::jacobian(ddq, v)),
                                     row_major(ADScalar::jacobian(ddq, a))}));
    }
}

int main(int argc, char **argv)
{
    if (argc < 3 || read_inputs(argv[1])) return 2;
    const std::string dir = std::string(argv[2]) + "/";
    // baked: the numeric model cast to SX
    {
        ModelTpl<double> model = build<double>(DH, LINKS, GRAV);
        ADModel ad = model.cast<ADScalar>();
        ::casadi::CodeGenerator gen("pin_baked.c", ::casadi::Dict{{"with_header", true}});
        add_functions(gen, ad, "pin_", {});
        gen.generate(dir);
    }
    // design as inputs: the model built from symbols
    {
        ADScalar dh = ADScalar::sym("dh", 4 * N), links = ADScalar::sym("links", 10 * N), g = ADScalar::sym("g", 3);
        std::vector<ADScalar> dhs, ls, gs;
        for (int k = 0; k < 4 * N; ++k) dhs.push_back(dh(k));
        for (int k = 0; k < 10 * N; ++k) ls.push_back(links(k));
        for (int k = 0; k < 3; ++k) gs.push_back(g(k));
        ADModel ad = build<ADScalar>(dhs.data(), ls.data(), gs.data());
        ::casadi::CodeGenerator gen("pin_design.c", ::casadi::Dict{{"with_header", true}});
        add_functions(gen, ad, "pind_", {dh, links, g});
        gen.generate(dir);
    }
    std::printf("{");
    for (size_t k = 0; k < COUNTS.size(); ++k)
        std::printf("%s\"%s\": %lld", k ? ", " : "", COUNTS[k].first.c_str(), COUNTS[k].second);
    std::printf("}\n");
    return 0;
}
