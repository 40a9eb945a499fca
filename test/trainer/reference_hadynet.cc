#include "reference_hadynet.h"

#include <cmath>

namespace hadynet::trainer::testing {

namespace {

double sigmoid(double v) { return 1.0 / (1.0 + std::exp(-v)); }

// Encoder pre-activations a = W_enc [x0 ; p] + b_enc of every window.
std::vector<Vec> encoder_pre(const HadynetParams<double>& P,
                             const std::vector<RefWindow>& windows) {
  const HadynetDims& d = P.dims;
  std::vector<Vec> pre;
  for (const RefWindow& w : windows) {
    Vec a(d.hidden);
    for (int i = 0; i < d.hidden; ++i) {
      double sum = P.enc_bias(i);
      for (int j = 0; j < d.x; ++j) sum += P.enc_weight(i, j) * w.x0[j];
      for (int j = 0; j < d.pb; ++j) sum += P.enc_weight(i, d.x + j) * w.p[j];
      a[i] = sum;
    }
    pre.push_back(a);
  }
  return pre;
}

// h_0 of every window: ReLU(BN(a)).
std::vector<Vec> encoder(const HadynetParams<double>& P, const std::vector<RefWindow>& windows,
                         BnMode mode) {
  const int H = P.dims.hidden;
  const std::vector<Vec> pre = encoder_pre(P, windows);
  const double count = static_cast<double>(windows.size());
  std::vector<Vec> h0(windows.size(), Vec(H));
  for (int i = 0; i < H; ++i) {
    double mean = P.enc_bn_running_mean(i);
    double var = P.enc_bn_running_var(i);
    if (mode == BnMode::kTrain) {
      mean = 0.0;
      for (const Vec& a : pre) mean += a[i];
      mean /= count;
      var = 0.0;
      for (const Vec& a : pre) var += (a[i] - mean) * (a[i] - mean);
      var /= count;
    }
    for (std::size_t b = 0; b < windows.size(); ++b) {
      const double z =
          P.enc_bn_weight(i) * (pre[b][i] - mean) / std::sqrt(var + kBnEps) + P.enc_bn_bias(i);
      h0[b][i] = z > 0.0 ? z : 0.0;
    }
  }
  return h0;
}

// One PyTorch LSTM step: (h, c) <- LSTM([u ; p], h, c).
void lstm_step(const HadynetParams<double>& P, const Vec& u, const Vec& p, Vec& h, Vec& c) {
  const HadynetDims& d = P.dims;
  const int H = d.hidden;
  Vec pre(4 * H);
  for (int r = 0; r < 4 * H; ++r) {
    double sum = P.lstm_bias_ih(r) + P.lstm_bias_hh(r);
    for (int j = 0; j < d.u; ++j) sum += P.lstm_weight_ih(r, j) * u[j];
    for (int j = 0; j < d.pb; ++j) sum += P.lstm_weight_ih(r, d.u + j) * p[j];
    for (int j = 0; j < H; ++j) sum += P.lstm_weight_hh(r, j) * h[j];
    pre[r] = sum;
  }
  for (int k = 0; k < H; ++k) {
    const double in = sigmoid(pre[k]);
    const double forget = sigmoid(pre[H + k]);
    const double cell = std::tanh(pre[2 * H + k]);
    const double out = sigmoid(pre[3 * H + k]);
    c[k] = forget * c[k] + in * cell;
    h[k] = out * std::tanh(c[k]);
  }
}

Vec decode(const HadynetParams<double>& P, const Vec& h) {
  const HadynetDims& d = P.dims;
  Vec y(d.y);
  for (int i = 0; i < d.y; ++i) {
    double sum = P.dec_bias(i);
    for (int j = 0; j < d.hidden; ++j) sum += P.dec_weight(i, j) * h[j];
    y[i] = sum;
  }
  return y;
}

}  // namespace

std::vector<RefWindow> to_reference(const WindowBatch<double>& batch,
                                    const HadynetParams<double>& params) {
  const int B = batch.windows();
  const int N = batch.steps();
  std::vector<RefWindow> windows(B);
  for (int b = 0; b < B; ++b) {
    RefWindow& w = windows[b];
    for (int j = 0; j < batch.x0.rows(); ++j) w.x0.push_back(batch.x0(j, b));
    for (int k = 0; k < N; ++k) {
      Vec u;
      for (int j = 0; j < batch.u.rows(); ++j) u.push_back(batch.u(j, k * B + b));
      w.u.push_back(u);
    }
    for (int j = 0; j < params.dims.pb; ++j) {
      w.p.push_back(batch.pb.size() != 0 ? batch.pb(j, b) : params.pb(batch.state[b], j));
    }
  }
  return windows;
}

std::vector<RefTrace> reference_forward(const HadynetParams<double>& params,
                                        const std::vector<RefWindow>& windows, BnMode mode) {
  const std::vector<Vec> h0 = encoder(params, windows, mode);
  std::vector<RefTrace> traces;
  for (std::size_t b = 0; b < windows.size(); ++b) {
    RefTrace t;
    Vec h = h0[b];
    Vec c(params.dims.hidden, 0.0);
    t.h.push_back(h);
    t.c.push_back(c);
    for (const Vec& u : windows[b].u) {
      lstm_step(params, u, windows[b].p, h, c);
      t.h.push_back(h);
      t.c.push_back(c);
      t.y.push_back(decode(params, h));
    }
    traces.push_back(t);
  }
  return traces;
}

std::vector<std::vector<Vec>> reference_truncated_outputs(const HadynetParams<double>& params,
                                                          const std::vector<RefWindow>& windows,
                                                          BnMode mode, int truncation,
                                                          const std::vector<RefTrace>& frozen) {
  const std::vector<Vec> h0 = encoder(params, windows, mode);
  std::vector<std::vector<Vec>> outputs(windows.size());
  for (std::size_t b = 0; b < windows.size(); ++b) {
    const int N = static_cast<int>(windows[b].u.size());
    for (int k = 0; k < N; ++k) {
      const int start = k - truncation + 1;
      Vec h = start >= 1 ? frozen[b].h[start] : h0[b];
      Vec c = start >= 1 ? frozen[b].c[start] : Vec(params.dims.hidden, 0.0);
      for (int j = start >= 1 ? start : 0; j <= k; ++j) {
        lstm_step(params, windows[b].u[j], windows[b].p, h, c);
      }
      outputs[b].push_back(decode(params, h));
    }
  }
  return outputs;
}

}  // namespace hadynet::trainer::testing
