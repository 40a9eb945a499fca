#include "trainer/hadynet_network.h"

#include "trainer/work_pool.h"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace hadynet::trainer {

namespace {

[[noreturn]] void shape_error(const std::string& what) {
  throw std::invalid_argument("HadynetNetwork: " + what);
}

std::string shape_str(Eigen::Index rows, Eigen::Index cols) {
  return std::to_string(rows) + "x" + std::to_string(cols);
}

// How the work of a forward or backward pass is split over training_pool():
// `count` items (windows, columns or gate rows) in chunks of at least
// `min_items` (smaller chunks lose more in matrix-product efficiency than a
// thread gains), one chunk per thread. (Two per thread, so that a thread on
// a shared core could take fewer, measured slower both on an idle machine,
// +5 %, and with one core busy, +4 %: bench/train_shared_core.sh.)
//
// Results do not depend on the split, hence not on the thread count: Eigen
// blocks a product's depth by the depth alone and computes each element in
// the same order wherever its row and column fall, PROVIDED the chunk
// boundaries fall on its register blocks: rows in panels of up to 3 SIMD
// registers (48 floats with AVX-512; 24 with AVX; 12 with SSE) and columns
// in groups of up to 8. Rows that fall in a panel's tail take another code
// path with another summation order. So chunk boundaries are multiples of
// kRowAlign rows or kColumnAlign columns (work_pool_test.cc checks the bits
// for 1, 2 and 3 threads at the paper's sizes).
constexpr int kRowAlign = 48;
constexpr int kColumnAlign = 8;

int chunks_for(int count, int min_items) {
  const int threads = training_pool().threads();
  if (threads == 1) return 1;
  return std::clamp(count / min_items, 1, threads);
}
// First item of chunk c of `chunks`, rounded down to a multiple of `align`
// (the last chunk ends at `count`; a chunk may be empty).
int chunk_begin(int c, int count, int chunks, int align) {
  if (c >= chunks) return count;
  return static_cast<int>(static_cast<long>(c) * count / chunks) / align * align;
}

}  // namespace

template <class S>
S mse_loss(const Matrix<S>& y_hat, const Matrix<S>& y, std::type_identity_t<Matrix<S>>* d_y_hat) {
  if (y_hat.rows() != y.rows() || y_hat.cols() != y.cols() || y.size() == 0) {
    shape_error("mse_loss: y_hat is " + shape_str(y_hat.rows(), y_hat.cols()) + ", y is " +
                shape_str(y.rows(), y.cols()));
  }
  const S count = static_cast<S>(y.size());
  if (d_y_hat != nullptr) {
    d_y_hat->noalias() = (S(2) / count) * (y_hat - y);
  }
  return (y_hat - y).squaredNorm() / count;
}

template <class S>
const Matrix<S>& HadynetNetwork<S>::forward(const HadynetParams<S>& params,
                                            const WindowBatch<S>& batch, BnMode mode) {
  params.check_shapes();
  const HadynetDims& d = params.dims;
  const int B = batch.windows();
  if (B < 1) shape_error("batch has no windows");
  if (batch.x0.rows() != d.x) {
    shape_error("x0 is " + shape_str(batch.x0.rows(), batch.x0.cols()) + ", expected " +
                std::to_string(d.x) + " rows");
  }
  if (batch.u.rows() != d.u || batch.u.cols() == 0 || batch.u.cols() % B != 0) {
    shape_error("u is " + shape_str(batch.u.rows(), batch.u.cols()) + ", expected " +
                std::to_string(d.u) + " x (N*" + std::to_string(B) + ")");
  }
  if (mode == BnMode::kTrain && B < 2) shape_error("BN training mode needs >= 2 windows");
  const bool explicit_pb = batch.pb.size() != 0;
  if (explicit_pb) {
    if (batch.pb.rows() != d.pb || batch.pb.cols() != B) {
      shape_error("pb is " + shape_str(batch.pb.rows(), batch.pb.cols()) + ", expected " +
                  shape_str(d.pb, B));
    }
  } else {
    if (static_cast<int>(batch.state.size()) != B) {
      shape_error("state has " + std::to_string(batch.state.size()) + " entries, expected " +
                  std::to_string(B));
    }
    for (int s : batch.state) {
      if (s < 0 || s >= d.states) {
        shape_error("state index " + std::to_string(s) + " outside [0, " +
                    std::to_string(d.states) + ")");
      }
    }
  }

  const int N = batch.steps();
  const int H = d.hidden;
  dims_ = d;
  batch_ = B;
  steps_ = N;
  mode_ = mode;
  explicit_pb_ = explicit_pb;
  state_ = explicit_pb ? std::vector<int>{} : batch.state;

  // ---- encoder: [x0 ; p] -> FC -> BN -> ReLU = h_0 ----
  enc_in_.resize(d.x + d.pb, B);
  enc_in_.topRows(d.x) = batch.x0;
  if (explicit_pb) {
    enc_in_.bottomRows(d.pb) = batch.pb;
  } else {
    for (int b = 0; b < B; ++b)
      enc_in_.col(b).tail(d.pb) = params.pb.row(batch.state[b]).transpose();
  }
  bn_out_.noalias() = params.enc_weight * enc_in_;  // pre-activation a, normalised below
  bn_out_.colwise() += params.enc_bias;
  if (mode == BnMode::kTrain) {
    bn_mean_ = bn_out_.rowwise().mean();
    bn_xhat_ = bn_out_.colwise() - bn_mean_;
    bn_var_ = bn_xhat_.array().square().rowwise().mean().matrix();
  } else {
    bn_mean_ = params.enc_bn_running_mean;
    bn_var_ = params.enc_bn_running_var;
    bn_xhat_ = bn_out_.colwise() - bn_mean_;
  }
  bn_invstd_ = (bn_var_.array() + static_cast<S>(kBnEps)).rsqrt().matrix();
  bn_xhat_.array().colwise() *= bn_invstd_.array();
  bn_out_.array() = (bn_xhat_.array().colwise() * params.enc_bn_weight.array()).colwise() +
                    params.enc_bn_bias.array();

  h_.resize(H, static_cast<Eigen::Index>(N + 1) * B);
  c_.resize(H, static_cast<Eigen::Index>(N + 1) * B);
  h_.leftCols(B) = bn_out_.cwiseMax(S(0));
  c_.leftCols(B).setZero();

  // ---- LSTM over N steps (forward_recurrence), windows split over threads ----
  const auto w_ih_p = params.lstm_weight_ih.rightCols(d.pb);
  gates_.resize(4 * H, static_cast<Eigen::Index>(N) * B);
  u_ = batch.u;
  gates_pb_.noalias() = w_ih_p * enc_in_.bottomRows(d.pb);
  gates_pb_.colwise() += params.lstm_bias_ih + params.lstm_bias_hh;
  tanh_c_.resize(H, static_cast<Eigen::Index>(N) * B);
  // Windows are independent through the recurrence: split them over threads.
  const int parts = chunks_for(B, 16);
  training_pool().run(parts, [&](int part) {
    const int b0 = chunk_begin(part, B, parts, kColumnAlign);
    const int nb = chunk_begin(part + 1, B, parts, kColumnAlign) - b0;
    if (nb > 0) forward_recurrence(params, b0, nb);
  });

  // ---- decoder, one step per chunk ----
  y_hat_.resize(d.y, static_cast<Eigen::Index>(N) * B);
  const int NB = N * B;
  const int column_chunks = chunks_for(NB, 64);
  training_pool().run(column_chunks, [&](int c) {
    const int c0 = chunk_begin(c, NB, column_chunks, kColumnAlign);
    auto y_c = y_hat_.middleCols(c0, chunk_begin(c + 1, NB, column_chunks, kColumnAlign) - c0);
    y_c.noalias() = params.dec_weight * h_.middleCols(B + c0, y_c.cols());
    y_c.colwise() += params.dec_bias;
  });
  return y_hat_;
}

// LSTM steps 0..N-1 for windows [b0, b0 + nb).
template <class S>
void HadynetNetwork<S>::forward_recurrence(const HadynetParams<S>& params, int b0, int nb) {
  const int H = dims_.hidden;
  const int B = batch_;
  const auto w_ih_u = params.lstm_weight_ih.leftCols(dims_.u);
  for (int k = 0; k < steps_; ++k) {
    auto g = gates_.middleCols(k * B + b0, nb);
    g.noalias() = w_ih_u * u_.middleCols(k * B + b0, nb);
    g += gates_pb_.middleCols(b0, nb);
    g.noalias() += params.lstm_weight_hh * h_.middleCols(k * B + b0, nb);
    g.topRows(2 * H) = g.topRows(2 * H).array().logistic();          // i, f
    g.middleRows(2 * H, H) = g.middleRows(2 * H, H).array().tanh();  // g
    g.bottomRows(H) = g.bottomRows(H).array().logistic();            // o
    const auto i = g.topRows(H).array();
    const auto f = g.middleRows(H, H).array();
    const auto gg = g.middleRows(2 * H, H).array();
    const auto o = g.bottomRows(H).array();
    auto c_next = c_.middleCols((k + 1) * B + b0, nb).array();
    c_next = f * c_.middleCols(k * B + b0, nb).array() + i * gg;
    auto tc = tanh_c_.middleCols(k * B + b0, nb).array();
    tc = c_next.tanh();
    h_.middleCols((k + 1) * B + b0, nb).array() = o * tc;
  }
}

template <class S>
void HadynetNetwork<S>::backward(const HadynetParams<S>& params, const Matrix<S>& d_y_hat,
                                 HadynetGrads<S>& grads, int truncation) {
  if (batch_ == 0) throw std::logic_error("HadynetNetwork::backward before forward");
  if (!(params.dims == dims_)) shape_error("backward: params dims differ from the forward's");
  if (truncation < 1)
    shape_error("truncation depth must be >= 1, got " + std::to_string(truncation));
  const HadynetDims& d = dims_;
  const int B = batch_;
  const Eigen::Index NB = static_cast<Eigen::Index>(steps_) * B;
  if (d_y_hat.rows() != d.y || d_y_hat.cols() != NB) {
    shape_error("d_y_hat is " + shape_str(d_y_hat.rows(), d_y_hat.cols()) + ", expected " +
                shape_str(d.y, NB));
  }
  if (!(grads.params.dims == d)) {
    grads.params = HadynetParams<S>::zeros(d);
  } else {
    // Every other gradient tensor is assigned in full below.
    grads.params.pb.setZero();
    grads.params.enc_bn_running_mean.setZero();
    grads.params.enc_bn_running_var.setZero();
  }
  HadynetParams<S>& g = grads.params;

  // decoder
  const auto h_next = h_.rightCols(NB);
  g.dec_weight.noalias() = d_y_hat * h_next.transpose();
  g.dec_bias = d_y_hat.rowwise().sum();
  d_h_out_.resize(d.hidden, NB);
  const int columns = static_cast<int>(NB);
  const int column_chunks = chunks_for(columns, 64);
  training_pool().run(column_chunks, [&](int c) {
    const int c0 = chunk_begin(c, columns, column_chunks, kColumnAlign);
    const int n = chunk_begin(c + 1, columns, column_chunks, kColumnAlign) - c0;
    d_h_out_.middleCols(c0, n).noalias() = params.dec_weight.transpose() * d_y_hat.middleCols(c0, n);
  });

  backward_recurrence(params, truncation);

  // LSTM parameters and inputs, all steps in one product each
  const auto w_ih_u = params.lstm_weight_ih.leftCols(d.u);
  const auto w_ih_p = params.lstm_weight_ih.rightCols(d.pb);
  const auto pb_in = enc_in_.bottomRows(d.pb);
  // dL/dW_hh (the largest product of a step) and dL/dW_ih of u, in fixed
  // chunks of gate rows over the pool.
  const int gate_rows = static_cast<int>(d_gates_.rows());
  const int row_chunks = chunks_for(gate_rows, 32);
  training_pool().run(row_chunks, [&](int c) {
    const int r0 = chunk_begin(c, gate_rows, row_chunks, kRowAlign);
    const int rows = chunk_begin(c + 1, gate_rows, row_chunks, kRowAlign) - r0;
    const auto d_gates_rows = d_gates_.middleRows(r0, rows);
    g.lstm_weight_hh.middleRows(r0, rows).noalias() = d_gates_rows * h_.leftCols(NB).transpose();
    g.lstm_weight_ih.leftCols(d.u).middleRows(r0, rows).noalias() = d_gates_rows * u_.transpose();
  });
  g.lstm_weight_ih.rightCols(d.pb).noalias() = d_gates_pb_sum_ * pb_in.transpose();
  g.lstm_bias_ih = d_gates_pb_sum_.rowwise().sum();
  g.lstm_bias_hh = g.lstm_bias_ih;
  grads.u.resize(d.u, NB);
  training_pool().run(column_chunks, [&](int c) {
    const int c0 = chunk_begin(c, columns, column_chunks, kColumnAlign);
    const int n = chunk_begin(c + 1, columns, column_chunks, kColumnAlign) - c0;
    grads.u.middleCols(c0, n).noalias() = w_ih_u.transpose() * d_gates_.middleCols(c0, n);
  });
  grads.pb_window.noalias() = w_ih_p.transpose() * d_gates_pb_sum_;

  backward_encoder(params, grads);

  if (!explicit_pb_) {
    for (int b = 0; b < B; ++b) g.pb.row(state_[b]) += grads.pb_window.col(b).transpose();
  }
}

// Fills d_gates_ (all steps), d_gates_pb_sum_ and d_h0_ from d_h_out_.
//
// Streams: a gradient that entered at output k and has passed a LSTM steps is
// "age a". At step j the live streams are block s = age s of d_h_in_/d_c_in_
// (block 0 = fresh gradient of output j). All live streams pass step j (their
// gate gradients are summed into d_gates_); only ages a <= K-2 continue to
// h_j, c_j (at step 0: every live stream reaches h_0, the encoder output).
// With full BPTT nothing is ever dropped, so all streams are summed into one.
template <class S>
void HadynetNetwork<S>::backward_recurrence(const HadynetParams<S>& params, int truncation) {
  const int H = dims_.hidden;
  const int B = batch_;
  const int N = steps_;
  const int max_streams = truncation >= N ? 1 : truncation;
  d_h_in_.resize(H, static_cast<Eigen::Index>(max_streams) * B);
  d_c_in_.resize(H, static_cast<Eigen::Index>(max_streams) * B);
  d_c_total_.resize(H, static_cast<Eigen::Index>(max_streams) * B);
  d_gates_streams_.resize(4 * H, static_cast<Eigen::Index>(max_streams) * B);
  d_gates_.resize(4 * H, static_cast<Eigen::Index>(N) * B);
  d_h0_.resize(H, B);
  // Windows are independent through the recurrence: split them over threads.
  const int parts = chunks_for(B, 16);
  training_pool().run(parts, [&](int part) {
    const int b0 = chunk_begin(part, B, parts, kColumnAlign);
    const int nb = chunk_begin(part + 1, B, parts, kColumnAlign) - b0;
    if (nb > 0) backward_recurrence_columns(params, truncation, b0, nb);
  });
  d_gates_pb_sum_ = d_gates_.leftCols(B);
  for (int k = 1; k < N; ++k) d_gates_pb_sum_ += d_gates_.middleCols(k * B, B);
}

// backward_recurrence for windows [b0, b0 + nb): block s of a stream matrix
// holds the stream of age s of every window, so this part's columns of block s
// are s*B + b0 .. s*B + b0 + nb - 1.
template <class S>
void HadynetNetwork<S>::backward_recurrence_columns(const HadynetParams<S>& params, int truncation,
                                                    int b0, int nb) {
  const int H = dims_.hidden;
  const int B = batch_;
  const int N = steps_;
  const bool full = truncation >= N;
  const auto block = [B, b0, nb](auto& m, int s) { return m.middleCols(s * B + b0, nb); };

  int carried = 0;  // streams propagated into this step from the later one
  for (int j = N - 1; j >= 0; --j) {
    const auto fresh = d_h_out_.middleCols(j * B + b0, nb);
    int live = 0;
    if (full) {
      if (carried > 0) {
        block(d_h_in_, 0) += fresh;
      } else {
        block(d_h_in_, 0) = fresh;
        block(d_c_in_, 0).setZero();
      }
      live = 1;
    } else {
      block(d_h_in_, 0) = fresh;
      block(d_c_in_, 0).setZero();
      live = 1 + carried;
    }

    const auto gates = gates_.middleCols(j * B + b0, nb);
    const auto i = gates.topRows(H).array();
    const auto f = gates.middleRows(H, H).array();
    const auto gg = gates.middleRows(2 * H, H).array();
    const auto o = gates.bottomRows(H).array();
    const auto tc = tanh_c_.middleCols(j * B + b0, nb).array();
    const auto c_prev = c_.middleCols(j * B + b0, nb).array();
    for (int s = 0; s < live; ++s) {
      const auto dh = block(d_h_in_, s).array();
      auto dc = block(d_c_total_, s).array();
      dc = block(d_c_in_, s).array() + dh * o * (S(1) - tc.square());
      auto da = block(d_gates_streams_, s);
      da.topRows(H).array() = dc * gg * i * (S(1) - i);
      da.middleRows(H, H).array() = dc * c_prev * f * (S(1) - f);
      da.middleRows(2 * H, H).array() = dc * i * (S(1) - gg.square());
      da.bottomRows(H).array() = dh * tc * o * (S(1) - o);
    }
    auto d_gates_j = d_gates_.middleCols(j * B + b0, nb);
    d_gates_j = block(d_gates_streams_, 0);
    for (int s = 1; s < live; ++s) d_gates_j += block(d_gates_streams_, s);

    if (j == 0) {
      // Every live stream has passed <= K steps: all reach the encoder output.
      d_h0_.middleCols(b0, nb).noalias() = params.lstm_weight_hh.transpose() * d_gates_j;
      break;
    }
    const int propagate = full ? 1 : std::min(live, truncation - 1);
    const int dest = full ? 0 : 1;  // block of age a+1 for the stream of age a
    for (int s = 0; s < propagate; ++s) {
      block(d_h_in_, s + dest).noalias() =
          params.lstm_weight_hh.transpose() * block(d_gates_streams_, s);
      block(d_c_in_, s + dest).array() = block(d_c_total_, s).array() * f;
    }
    carried = propagate;
  }
}

template <class S>
void HadynetNetwork<S>::backward_encoder(const HadynetParams<S>& params, HadynetGrads<S>& grads) {
  const HadynetDims& d = dims_;
  HadynetParams<S>& g = grads.params;
  // ReLU: d_h0_ becomes dL/d(bn_out)
  d_h0_.array() = (bn_out_.array() > S(0)).select(d_h0_.array(), S(0));
  g.enc_bn_weight = (d_h0_.array() * bn_xhat_.array()).rowwise().sum().matrix();
  g.enc_bn_bias = d_h0_.rowwise().sum();
  // d_h0_ becomes dL/dxhat
  d_h0_.array().colwise() *= params.enc_bn_weight.array();
  if (mode_ == BnMode::kTrain) {
    // Batch statistics depend on every window:
    // da = invstd/B * (B dxhat - sum_b dxhat - xhat * sum_b(dxhat * xhat))
    const S count = static_cast<S>(batch_);
    const Vector<S> sum_dxhat = d_h0_.rowwise().sum();
    const Vector<S> sum_dxhat_xhat = (d_h0_.array() * bn_xhat_.array()).rowwise().sum().matrix();
    d_h0_.array() = count * d_h0_.array() - (bn_xhat_.array().colwise() * sum_dxhat_xhat.array());
    d_h0_.colwise() -= sum_dxhat;
    d_h0_.array().colwise() *= bn_invstd_.array() / count;
  } else {
    d_h0_.array().colwise() *= bn_invstd_.array();
  }
  // d_h0_ is now dL/da, a = W_enc [x ; p] + b_enc
  g.enc_weight.noalias() = d_h0_ * enc_in_.transpose();
  g.enc_bias = d_h0_.rowwise().sum();
  grads.pb_window.noalias() += params.enc_weight.rightCols(d.pb).transpose() * d_h0_;
}

template <class S>
void HadynetNetwork<S>::update_bn_running_stats(HadynetParams<S>& params, double momentum) const {
  if (batch_ == 0 || mode_ != BnMode::kTrain) {
    throw std::logic_error("update_bn_running_stats needs a preceding BN training-mode forward");
  }
  if (!(params.dims == dims_)) shape_error("update_bn_running_stats: params dims differ");
  const S m = static_cast<S>(momentum);
  const S unbias = static_cast<S>(batch_) / static_cast<S>(batch_ - 1);
  params.enc_bn_running_mean = (S(1) - m) * params.enc_bn_running_mean + m * bn_mean_;
  params.enc_bn_running_var = (S(1) - m) * params.enc_bn_running_var + (m * unbias) * bn_var_;
}

template float mse_loss<float>(const Matrix<float>&, const Matrix<float>&, Matrix<float>*);
template double mse_loss<double>(const Matrix<double>&, const Matrix<double>&, Matrix<double>*);
template class HadynetNetwork<float>;
template class HadynetNetwork<double>;

}  // namespace hadynet::trainer
