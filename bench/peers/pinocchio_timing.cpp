// Pinocchio's C++ algorithms (double) on the chain and states of bench/native.py's input file:
// the same round-robin timing as apair's program, the same output layout for the agreement check.
//   pinocchio_timing INPUT OUTPUT ROUNDS
// The chain is built from its DH constants as bench/run.py's pin_model does: revolute joints about
// z, joint i placed at D_{i-1} = Rz(phi) Tz(c) Tx(a) Rx(alpha) of the joint before, link i's inertia
// given in frame i (moved by D_i into joint i's frame), a frame "end" at D_n.
#include <pinocchio/algorithm/aba.hpp>
#include <pinocchio/algorithm/crba.hpp>
#include <pinocchio/algorithm/frames.hpp>
#include <pinocchio/algorithm/jacobian.hpp>
#include <pinocchio/algorithm/kinematics.hpp>
#include <pinocchio/algorithm/rnea.hpp>
#include <pinocchio/multibody.hpp>

#include <vector>

#include "bench_inputs.h"

using namespace pinocchio;

static SE3 rot(int axis, double angle)
{
    Eigen::Matrix3d R = Eigen::AngleAxisd(angle, axis == 0 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitZ())
                            .toRotationMatrix();
    return SE3(R, Eigen::Vector3d::Zero());
}

static SE3 trans(double x, double y, double z)
{
    return SE3(Eigen::Matrix3d::Identity(), Eigen::Vector3d(x, y, z));
}

static Model build_model()
{
    Model model;
    JointIndex parent = 0;
    SE3 placement = SE3::Identity();
    for (int i = 0; i < N; ++i) {
        parent = model.addJoint(parent, JointModelRZ(), placement, "r" + std::to_string(i));
        const double a = DH[4 * i], alpha = DH[4 * i + 1], c = DH[4 * i + 2], phi = DH[4 * i + 3];
        SE3 D = rot(2, phi) * trans(0, 0, c) * trans(a, 0, 0) * rot(0, alpha);
        const double *L = LINKS + 10 * i;
        Eigen::Matrix3d I;
        I << L[4], L[7], L[8], L[7], L[5], L[9], L[8], L[9], L[6];
        model.appendBodyToJoint(parent, D.act(Inertia(L[0], Eigen::Vector3d(L[1], L[2], L[3]), I)), SE3::Identity());
        placement = D;
    }
    model.addFrame(Frame("end", parent, 0, placement, OP_FRAME));
    model.gravity = Motion(Eigen::Vector3d(GRAV[0], GRAV[1], GRAV[2]), Eigen::Vector3d::Zero());
    return model;
}

int main(int argc, char **argv)
{
    if (argc < 4 || read_inputs(argv[1])) return 2;
    const int rounds = std::atoi(argv[3]);
    Model model = build_model();
    Data data(model);
    const FrameIndex fid = model.getFrameId("end");
    const int n = N;
    const long checked = COUNT < 16 ? COUNT : 16;
    std::vector<double> outT(16 * checked), outJ(6 * n * checked), outM(n * n * checked), outTau(n * checked),
        outQdd(n * checked);
    Data::Matrix6x J(6, n);
    double best[5] = {1e300, 1e300, 1e300, 1e300, 1e300};
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
    }
    FILE *f = std::fopen(argv[2], "wb");
    std::fwrite(outT.data(), sizeof(double), outT.size(), f);
    std::fwrite(outJ.data(), sizeof(double), outJ.size(), f);
    std::fwrite(outM.data(), sizeof(double), outM.size(), f);
    std::fwrite(outTau.data(), sizeof(double), outTau.size(), f);
    std::fwrite(outQdd.data(), sizeof(double), outQdd.size(), f);
    std::fclose(f);
    std::printf("{\"fk\": %.3f, \"jacobian\": %.3f, \"mass_matrix\": %.3f, \"inverse_dynamics\": %.3f, "
                "\"forward_dynamics\": %.3f, \"sink\": %.3g}\n",
                best[0], best[1], best[2], best[3], best[4], sink);
    return 0;
}
