#include "trainer/data_hash.h"
#include "trainer/deploy_prep.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>

namespace hadynet::trainer {

namespace {

template <class M>
double max_abs(const M& m) {
  return m.size() == 0 ? 0.0 : static_cast<double>(m.cwiseAbs().maxCoeff());
}

}  // namespace

ValueRanges measure_ranges(const HadynetModel& model, const WindowDataset& data,
                           std::span<const int> ids) {
  const HadynetParams<float>& p = model.params;
  const FoldedEncoder enc = fold_batch_norm(p);
  ValueRanges r;
  r.pb = max_abs(p.pb);
  r.enc_weight = max_abs(enc.weight);
  r.enc_bias = max_abs(enc.bias);
  r.lstm_weight = std::max(max_abs(p.lstm_weight_ih), max_abs(p.lstm_weight_hh));
  r.lstm_bias = max_abs(p.lstm_bias_ih + p.lstm_bias_hh);
  r.dec_weight = max_abs(p.dec_weight);
  r.dec_bias = max_abs(p.dec_bias);

  HadynetNetwork<float> net;
  WindowBatch<float> batch;
  Matrix<float> y;
  constexpr std::size_t kChunk = 1000;
  for (std::size_t begin = 0; begin < ids.size(); begin += kChunk) {
    const std::size_t n = std::min(kChunk, ids.size() - begin);
    data.gather(ids.subspan(begin, n), batch, y);
    const Matrix<float>& y_hat = net.forward(p, batch, BnMode::kEval);
    const auto B = static_cast<Eigen::Index>(n);
    const Eigen::Index N = data.steps();
    Matrix<float> pb(p.dims.pb, B);
    for (Eigen::Index b = 0; b < B; ++b)
      pb.col(b) = p.pb.row(batch.state[static_cast<std::size_t>(b)]).transpose();
    Matrix<float> enc_in(p.dims.x + p.dims.pb, B);
    enc_in << batch.x0, pb;
    const Matrix<float> enc_pre = (enc.weight * enc_in).colwise() + enc.bias;
    const Matrix<float>& h = net.hidden_states();
    const Vector<float> bias = p.lstm_bias_ih + p.lstm_bias_hh;
    const Matrix<float> pb_steps = pb.replicate(1, N);  // step-major like batch.u
    const Matrix<float> gate_pre =
        ((p.lstm_weight_ih.leftCols(p.dims.u) * batch.u +
          p.lstm_weight_ih.rightCols(p.dims.pb) * pb_steps +
          p.lstm_weight_hh * h.leftCols(N * B))
             .colwise() +
         bias);
    r.x = std::max(r.x, max_abs(batch.x0));
    r.u = std::max(r.u, max_abs(batch.u));
    r.enc_pre = std::max(r.enc_pre, max_abs(enc_pre));
    r.h = std::max(r.h, max_abs(h));
    r.gate_pre = std::max(r.gate_pre, max_abs(gate_pre));
    r.c = std::max(r.c, max_abs(net.cell_states()));
    r.y = std::max(r.y, max_abs(y_hat));
  }
  r.windows = static_cast<long>(ids.size());
  return r;
}

ValueRanges measure_log_ranges(const HadynetModel& model, const std::vector<std::string>& log_args) {
  const std::vector<std::string> paths = expand_log_paths(log_args);
  std::vector<LogSequence> sequences;
  std::vector<int> rows;
  for (const std::string& path : paths) {
    sequences.push_back(read_sequence(path, model.layout));
    const int row = model.state_index(sequences.back().state);
    if (row < 0) {
      throw std::runtime_error(path + ": state '" + sequences.back().state +
                               "' is not in the model's PB table");
    }
    rows.push_back(row);
  }
  const WindowDataset data(sequences, rows, model.layout, model.norm, model.train_steps);
  if (data.size() == 0) {
    throw std::runtime_error("the logs hold no window of " + std::to_string(model.train_steps) +
                             " steps");
  }
  std::vector<int> ids(static_cast<std::size_t>(data.size()));
  std::iota(ids.begin(), ids.end(), 0);
  ValueRanges r = measure_ranges(model, data, ids);
  std::string args;
  for (const std::string& a : log_args) args += (args.empty() ? "" : " ") + a;
  r.source = args + ": " + std::to_string(paths.size()) + " logs (data_hash " +
             data_hash(paths) + "), all windows of " + std::to_string(model.train_steps) +
             " steps";
  return r;
}

}  // namespace hadynet::trainer
