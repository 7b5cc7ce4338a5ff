// Pinocchio's C++ algorithms (double) on the model and states of bench/native.py's input files:
// the same round-robin timing as apair's program, the same output layout for the agreement check.
// After fk, the frame Jacobian, crba, rnea and aba, the derivatives of the dynamics:
// computeRNEADerivatives (dtau_dq, dtau_dv; it also fills M = dtau_da, not written) and
// computeABADerivatives (ddq_dq, ddq_dv, Minv, whose upper triangle only Pinocchio fills: it is
// written symmetrised), each written as n x n row-major blocks.
//   pinocchio_timing INPUT OUTPUT ROUNDS MODEL
// MODEL (bench/native.py's write_pin_model, from a pinocchio.Model built in Python: the DH chain's
// or a URDF's) holds the kinematic tree as doubles: the joint count, then per joint its type (0, 1,
// 2: revolute about x, y, z; 3: revolute about the unit axis that follows), the axis, the parent
// joint, the placement in the parent (R row by row, then t) and the body's inertia (mass, centre of
// mass, 3 x 3 inertia about it, in the joint's frame); then the timed frame (parent joint,
// placement) and the gravity. The model is rebuilt here with addJoint and appendBodyToJoint, so the
// algorithms see the model Pinocchio's own builders (DH or URDF) make.
#include <pinocchio/algorithm/aba-derivatives.hpp>
#include <pinocchio/algorithm/aba.hpp>
#include <pinocchio/algorithm/crba.hpp>
#include <pinocchio/algorithm/frames.hpp>
#include <pinocchio/algorithm/jacobian.hpp>
#include <pinocchio/algorithm/kinematics.hpp>
#include <pinocchio/algorithm/rnea-derivatives.hpp>
#include <pinocchio/algorithm/rnea.hpp>
#include <pinocchio/multibody.hpp>

#include <string>
#include <vector>

#include "bench_inputs.h"

using namespace pinocchio;

static SE3 placement_of(const double *p)
{
    Eigen::Matrix3d R;
    R << p[0], p[1], p[2], p[3], p[4], p[5], p[6], p[7], p[8];
    return SE3(R, Eigen::Vector3d(p[9], p[10], p[11]));
}

// the n x n matrix A (its upper triangle only if `upper`, mirrored) row-major at out
static void write_square(const Eigen::MatrixXd &A, bool upper, double *out)
{
    const int n = (int)A.rows();
    for (int r = 0; r < n; ++r)
        for (int c = 0; c < n; ++c) out[n * r + c] = upper && r > c ? A(c, r) : A(r, c);
}

static bool read_model(const char *path, Model &model, FrameIndex &fid)
{
    FILE *f = std::fopen(path, "rb");
    if (!f) return false;
    std::vector<double> d;
    double x;
    while (std::fread(&x, sizeof(double), 1, f) == 1) d.push_back(x);
    std::fclose(f);
    if (d.empty()) return false;
    const int joints = (int)d[0];
    const size_t per_joint = 1 + 3 + 1 + 12 + 1 + 3 + 9, size = 1 + joints * per_joint + 13 + 3;
    if (joints != N || d.size() != size) return false;
    const double *p = d.data() + 1;
    for (int j = 0; j < joints; ++j, p += per_joint) {
        const int type = (int)p[0];
        const Eigen::Vector3d axis(p[1], p[2], p[3]);
        JointModel joint = type == 0   ? JointModel(JointModelRX())
                           : type == 1 ? JointModel(JointModelRY())
                           : type == 2 ? JointModel(JointModelRZ())
                                       : JointModel(JointModelRevoluteUnaligned(axis));
        const JointIndex id = model.addJoint((JointIndex)p[4], joint, placement_of(p + 5), "j" + std::to_string(j));
        Eigen::Matrix3d I;
        I << p[21], p[22], p[23], p[24], p[25], p[26], p[27], p[28], p[29];
        model.appendBodyToJoint(id, Inertia(p[17], Eigen::Vector3d(p[18], p[19], p[20]), I), SE3::Identity());
    }
    fid = model.addFrame(Frame("end", (JointIndex)p[0], 0, placement_of(p + 1), OP_FRAME));
    model.gravity = Motion(Eigen::Vector3d(p[13], p[14], p[15]), Eigen::Vector3d::Zero());
    return true;
}

int main(int argc, char **argv)
{
    if (argc < 5 || read_inputs(argv[1])) return 2;
    const int rounds = std::atoi(argv[3]);
    Model model;
    FrameIndex fid = 0;
    if (!read_model(argv[4], model, fid)) return 3;
    Data data(model);
    const int n = N;
    const long checked = COUNT < 16 ? COUNT : 16;
    std::vector<double> outT(16 * checked), outJ(6 * n * checked), outM(n * n * checked), outTau(n * checked),
        outQdd(n * checked);
    const long sq = n * n * checked;
    std::vector<double> outDtauDq(sq), outDtauDv(sq), outDdqDq(sq), outDdqDv(sq), outMinv(sq);
    Data::Matrix6x J(6, n);
    double best[7] = {1e300, 1e300, 1e300, 1e300, 1e300, 1e300, 1e300};
    double sink = 0;
    using Vec = Eigen::Map<const Eigen::VectorXd>;
    for (int round = 0; round <= rounds; ++round) {  // round 0: warm-up
        double t0 = now_ns();
        for (long k = 0; k < COUNT; ++k) {
            forwardKinematics(model, data, Vec(&Q[k * n], n));
            updateFramePlacement(model, data, fid);
            if (k < checked) {
                Eigen::Matrix4d H = data.oMf[fid].toHomogeneousMatrix();
                for (int r = 0; r < 4; ++r)
                    for (int c = 0; c < 4; ++c) outT[16 * k + 4 * r + c] = H(r, c);
            }
        }
        double t = (now_ns() - t0) / COUNT;
        if (round > 0 && t < best[0]) best[0] = t;
        t0 = now_ns();
        for (long k = 0; k < COUNT; ++k) {
            J.setZero();
            computeFrameJacobian(model, data, Vec(&Q[k * n], n), fid, LOCAL_WORLD_ALIGNED, J);
            if (k < checked)
                for (int r = 0; r < 6; ++r)
                    for (int c = 0; c < n; ++c) outJ[6 * n * k + n * r + c] = J(r, c);
        }
        t = (now_ns() - t0) / COUNT;
        if (round > 0 && t < best[1]) best[1] = t;
        t0 = now_ns();
        for (long k = 0; k < COUNT; ++k) {
            crba(model, data, Vec(&Q[k * n], n));
            if (k < checked)
                for (int r = 0; r < n; ++r)
                    for (int c = 0; c < n; ++c) outM[n * n * k + n * r + c] = r <= c ? data.M(r, c) : data.M(c, r);
        }
        t = (now_ns() - t0) / COUNT;
        if (round > 0 && t < best[2]) best[2] = t;
        t0 = now_ns();
        for (long k = 0; k < COUNT; ++k) {
            const Eigen::VectorXd &tau = rnea(model, data, Vec(&Q[k * n], n), Vec(&QD[k * n], n), Vec(&QDD[k * n], n));
            if (k < checked)
                for (int r = 0; r < n; ++r) outTau[n * k + r] = tau[r];
        }
        t = (now_ns() - t0) / COUNT;
        if (round > 0 && t < best[3]) best[3] = t;
        t0 = now_ns();
        for (long k = 0; k < COUNT; ++k) {
            const Eigen::VectorXd &qdd = aba(model, data, Vec(&Q[k * n], n), Vec(&QD[k * n], n), Vec(&TAU[k * n], n));
            if (k < checked)
                for (int r = 0; r < n; ++r) outQdd[n * k + r] = qdd[r];
            sink += qdd[0];
        }
        t = (now_ns() - t0) / COUNT;
        if (round > 0 && t < best[4]) best[4] = t;
        t0 = now_ns();
        for (long k = 0; k < COUNT; ++k) {
            computeRNEADerivatives(model, data, Vec(&Q[k * n], n), Vec(&QD[k * n], n), Vec(&QDD[k * n], n));
            if (k < checked) {
                write_square(data.dtau_dq, false, &outDtauDq[n * n * k]);
                write_square(data.dtau_dv, false, &outDtauDv[n * n * k]);
            }
            sink += data.dtau_dq(0, 0);
        }
        t = (now_ns() - t0) / COUNT;
        if (round > 0 && t < best[5]) best[5] = t;
        t0 = now_ns();
        for (long k = 0; k < COUNT; ++k) {
            computeABADerivatives(model, data, Vec(&Q[k * n], n), Vec(&QD[k * n], n), Vec(&TAU[k * n], n));
            if (k < checked) {
                write_square(data.ddq_dq, false, &outDdqDq[n * n * k]);
                write_square(data.ddq_dv, false, &outDdqDv[n * n * k]);
                write_square(data.Minv, true, &outMinv[n * n * k]);
            }
            sink += data.ddq_dq(0, 0);
        }
        t = (now_ns() - t0) / COUNT;
        if (round > 0 && t < best[6]) best[6] = t;
    }
    FILE *f = std::fopen(argv[2], "wb");
    std::fwrite(outT.data(), sizeof(double), outT.size(), f);
    std::fwrite(outJ.data(), sizeof(double), outJ.size(), f);
    std::fwrite(outM.data(), sizeof(double), outM.size(), f);
    std::fwrite(outTau.data(), sizeof(double), outTau.size(), f);
    std::fwrite(outQdd.data(), sizeof(double), outQdd.size(), f);
    for (const std::vector<double> *out : {&outDtauDq, &outDtauDv, &outDdqDq, &outDdqDv, &outMinv})
        std::fwrite(out->data(), sizeof(double), out->size(), f);
    std::fclose(f);
    std::printf("{\"fk\": %.3f, \"jacobian\": %.3f, \"mass_matrix\": %.3f, \"inverse_dynamics\": %.3f, "
                "\"forward_dynamics\": %.3f, \"inverse_dynamics_derivatives\": %.3f, "
                "\"forward_dynamics_derivatives\": %.3f, \"sink\": %.3g}\n",
                best[0], best[1], best[2], best[3], best[4], best[5], best[6], sink);
    return 0;
}
