// A C interface to Pinocchio's C++ for the benchmark beside moreau
// (benches/benches/vs_pinocchio.rs): load a model that Pinocchio's Python
// bindings built from a URDF and saved as a text archive (the wheel ships
// no urdfdom headers, so the C++ side cannot parse the URDF itself), then
// CRBA + nonlinear effects, the two calls that give M and C v + G.
#include <string>

#include <pinocchio/algorithm/crba.hpp>
#include <pinocchio/algorithm/rnea.hpp>
#include <pinocchio/multibody.hpp>
#include <pinocchio/serialization.hpp>

namespace {
struct Robot {
  pinocchio::Model model;
  pinocchio::Data data;
  Eigen::VectorXd q, v;
};
}  // namespace

extern "C" {

// The model saved by `Model.saveToText` at `path`; null if it cannot be
// loaded or has a joint of more than one coordinate.
void* moreau_pin_load(const char* path) {
  try {
    auto* r = new Robot();
    r->model.loadFromText(std::string(path));
    if (r->model.nq != r->model.nv) {
      delete r;
      return nullptr;
    }
    r->data = pinocchio::Data(r->model);
    r->q = Eigen::VectorXd::Zero(r->model.nq);
    r->v = Eigen::VectorXd::Zero(r->model.nv);
    return r;
  } catch (...) {
    return nullptr;
  }
}

int moreau_pin_nv(const void* robot) { return static_cast<const Robot*>(robot)->model.nv; }

// M (upper triangle filled by CRBA, lower mirrored here, column-major into
// `mass`) and C v + G into `nle`, at (q, v).
void moreau_pin_crba_nle(void* robot, const double* q, const double* v, double* mass, double* nle) {
  auto* r = static_cast<Robot*>(robot);
  const int n = r->model.nv;
  r->q = Eigen::Map<const Eigen::VectorXd>(q, n);
  r->v = Eigen::Map<const Eigen::VectorXd>(v, n);
  pinocchio::crba(r->model, r->data, r->q);
  pinocchio::nonLinearEffects(r->model, r->data, r->q, r->v);
  r->data.M.triangularView<Eigen::StrictlyLower>() =
      r->data.M.transpose().triangularView<Eigen::StrictlyLower>();
  Eigen::Map<Eigen::MatrixXd>(mass, n, n) = r->data.M;
  Eigen::Map<Eigen::VectorXd>(nle, n) = r->data.nle;
}

void moreau_pin_free(void* robot) { delete static_cast<Robot*>(robot); }
}
