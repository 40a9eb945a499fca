// The C++ network against PyTorch: forward (BN eval and train), the MSE loss
// and every gradient of HadynetNetwork<double> against the same network in
// PyTorch float64 (bench/torch_baseline.py's module), from a fixture that
// PyTorch wrote (fixtures/make_torch_fixture.py; checked in, so this test
// needs no PyTorch). An independent reference: nothing of the C++ code went
// into it, only the PyTorch state_dict names and layouts the model file uses.
//
// Tolerance 1e-10, absolute, on values of order 1: both sides compute in
// double, so they differ only by summation order (about 1e-15 per operation
// over a few hundred operations); any formula error (a gate order, a BN
// variance without the eps, a transposed weight, a missing PB path) changes
// results by 1e-3 or more.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "trainer/hadynet_network.h"
#include "trainer/hadynet_params.h"
#include "trainer/safetensors.h"

namespace hadynet::trainer {
namespace {

namespace st = safetensors;

constexpr double kTolerance = 1e-10;

struct Fixture {
  st::File file = st::read_file(HADYNET_TORCH_FIXTURE);
  // Sizes: every dimension different (see the generator).
  HadynetDims dims{.x = 5, .u = 3, .y = 4, .pb = 2, .hidden = 6, .states = 3};
  int windows = 4, steps = 7;

  std::vector<double> get(const std::string& name, std::vector<std::int64_t> shape) const {
    return st::as_f64(file, name, shape);
  }

  // PyTorch's state_dict values, by name, into the C++ parameters; with a
  // prefix ("grad."), the gradients of the trainable ones (the others stay 0).
  HadynetParams<double> params(const std::string& prefix = "") const {
    HadynetParams<double> p = HadynetParams<double>::zeros(dims);
    for (NamedTensor<double> t : p.tensors()) {
      if (!prefix.empty() && !t.trainable) continue;
      std::vector<std::int64_t> shape{t.rows};
      if (t.rank == 2) shape.push_back(t.cols);
      const std::vector<double> v = get(prefix + std::string(t.name), shape);
      for (std::size_t i = 0; i < v.size(); ++i) t.data[i] = v[i];
    }
    return p;
  }

  WindowBatch<double> batch() const {
    WindowBatch<double> b;
    const std::vector<double> x0 = get("in.x0", {windows, dims.x});
    const std::vector<double> u = get("in.u", {windows, steps, dims.u});
    b.x0.resize(dims.x, windows);
    for (int w = 0; w < windows; ++w)
      for (int i = 0; i < dims.x; ++i) b.x0(i, w) = x0[static_cast<std::size_t>(w * dims.x + i)];
    b.u = step_major(u, dims.u);
    for (std::int32_t s : st::as_i32(file, "in.state", {windows})) b.state.push_back(s);
    return b;
  }

  // PyTorch (B, N, C), row-major -> C x (N*B), column k*B + b = step k of window b.
  Matrix<double> step_major(const std::vector<double>& v, int channels) const {
    Matrix<double> m(channels, steps * windows);
    for (int w = 0; w < windows; ++w)
      for (int k = 0; k < steps; ++k)
        for (int c = 0; c < channels; ++c)
          m(c, k * windows + w) = v[static_cast<std::size_t>((w * steps + k) * channels + c)];
    return m;
  }
};

// `nonzero`: the reference must be large enough to test anything.
void expect_near(const Matrix<double>& got, const Matrix<double>& want, const std::string& what,
                 bool nonzero = true) {
  ASSERT_EQ(got.rows(), want.rows()) << what;
  ASSERT_EQ(got.cols(), want.cols()) << what;
  EXPECT_LE((got - want).cwiseAbs().maxCoeff(), kTolerance) << what;
  if (nonzero) {
    EXPECT_GT(want.cwiseAbs().maxCoeff(), 1e-3) << what << ": the reference is too small to test anything";
  }
}

TEST(TorchReference, ForwardWithBatchNormInEvalMode) {
  const Fixture f;
  HadynetNetwork<double> net;
  const Matrix<double>& y_hat = net.forward(f.params(), f.batch(), BnMode::kEval);
  expect_near(y_hat, f.step_major(f.get("out.y_hat.eval", {f.windows, f.steps, f.dims.y}), f.dims.y), "y_hat (eval)");
}

TEST(TorchReference, ForwardLossAndEveryGradientInTrainMode) {
  const Fixture f;
  const HadynetParams<double> params = f.params();
  const WindowBatch<double> batch = f.batch();
  HadynetNetwork<double> net;
  const Matrix<double> y_hat = net.forward(params, batch, BnMode::kTrain);
  expect_near(y_hat, f.step_major(f.get("out.y_hat.train", {f.windows, f.steps, f.dims.y}), f.dims.y),
              "y_hat (train)");

  const Matrix<double> y = f.step_major(f.get("in.y", {f.windows, f.steps, f.dims.y}), f.dims.y);
  Matrix<double> d_y_hat;
  const double loss = mse_loss(y_hat, y, &d_y_hat);
  EXPECT_NEAR(loss, f.get("out.loss.train", {}).at(0), kTolerance);

  HadynetGrads<double> grads;
  net.backward(params, d_y_hat, grads);
  const HadynetParams<double> want = f.params("grad.");  // PyTorch has no gradient of BN statistics
  const auto got_tensors = grads.params.tensors();
  const auto want_tensors = want.tensors();
  int compared = 0;
  for (std::size_t i = 0; i < got_tensors.size(); ++i) {
    const auto& g = got_tensors[i];
    if (!g.trainable) continue;
    const Eigen::Map<const Matrix<double>> gm(g.data, g.cols, g.rows);  // row-major data as cols x rows
    const Eigen::Map<const Matrix<double>> wm(want_tensors[i].data, g.cols, g.rows);
    // In train mode BN subtracts the batch mean, which cancels the encoder
    // bias: its gradient is 0 on both sides (to rounding).
    expect_near(gm, wm, "gradient of " + std::string(g.name), g.name != "enc.bias");
    ++compared;
  }
  EXPECT_EQ(compared, 11);  // every tensor but the two BN running statistics
  expect_near(grads.u, f.step_major(f.get("grad.u", {f.windows, f.steps, f.dims.u}), f.dims.u), "gradient of u");
}

}  // namespace
}  // namespace hadynet::trainer
