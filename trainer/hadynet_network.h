// HADYNET forward pass and exact back-propagation through time over a batch
// of windows (docs/method.md, "Network"):
//
//   z0        = ReLU(BN(W_enc [x ; p] + b_enc))          h_0 = z0, c_0 = 0
//   h_{k+1}   = LSTM([u_k ; p], h_k, c_k)                 PyTorch LSTM, gates i, f, g, o
//   y_hat_k   = W_dec h_{k+1} + b_dec                     k = 0 .. N-1 (predicts y_{t+k+1})
//
// Batch layout: the batch runs along COLUMNS. Column b of a per-window matrix
// is window b (B = number of windows). Matrices over time are step-major:
// column k*B + b holds step k of window b, so step k is the contiguous block
// middleCols(k*B, B). Units are those of the (standardised) data.
#pragma once

#include <limits>
#include <type_traits>
#include <vector>

#include "trainer/hadynet_params.h"

namespace hadynet::trainer {

// Batch norm of the encoder output. kTrain: batch mean and biased batch
// variance (needs B >= 2); kEval: running statistics. eps = 1e-5 in both.
enum class BnMode { kTrain, kEval };

inline constexpr double kBnMomentum = 0.1;  // (kBnEps: hadynet_params.h)

// Truncation depth meaning "full BPTT" (any value >= N does the same).
inline constexpr int kFullBptt = std::numeric_limits<int>::max();

// B windows of N steps.
template <class S>
struct WindowBatch {
  Matrix<S> x0;            // dims.x x B: initial state x_t of each window
  Matrix<S> u;             // dims.u x (N*B), step-major: commands u_{t+k}
  std::vector<int> state;  // B rows of the PB table; used when `pb` is empty
  Matrix<S> pb;            // dims.pb x B: explicit PB per window; if non-empty it
                           // replaces `state` (and no PB-table gradient is made)

  int windows() const { return static_cast<int>(x0.cols()); }
  int steps() const { return windows() == 0 ? 0 : static_cast<int>(u.cols()) / windows(); }
};

template <class S>
struct HadynetGrads {
  HadynetParams<S> params;  // dL/d(each parameter), same shapes. BN running stats: 0.
                            // pb: row k = sum of pb_window over windows with state k
                            // (all zero when the batch had an explicit PB).
  Matrix<S> u;              // dL/du, dims.u x (N*B), layout of WindowBatch::u
  Matrix<S> pb_window;      // dL/dp of each window's PB, dims.pb x B
                            // (encoder input plus every LSTM step)
};

// Mean squared error over all steps, channels and windows:
//   L = 1/(N*B*dims.y) * sum_{k,b,j} (y_hat - y)^2      (PyTorch MSELoss, reduction "mean")
// y_hat and y: dims.y x (N*B), step-major; y column k*B+b is y_{t+k+1} of window b.
// If d_y_hat is not null it receives dL/dy_hat = 2 (y_hat - y) / (N*B*dims.y).
template <class S>
S mse_loss(const Matrix<S>& y_hat, const Matrix<S>& y,
           std::type_identity_t<Matrix<S>>* d_y_hat = nullptr);

// Holds the activations of the last forward pass that backward needs, and
// scratch buffers reused between calls (no allocation once shapes settle).
// Threads: the recurrence of forward and backward runs in parts of the
// windows (windows are independent there), the decoder and the input
// gradients in steps, and the largest weight gradients in chunks of gate
// rows, all on training_pool() (work_pool.h). Results are bit-identical for
// any thread count (hadynet_network.cc, chunks_for()).
template <class S>
class HadynetNetwork {
 public:
  // Runs the network. Does not modify `params`; in kTrain the batch statistics
  // are kept for update_bn_running_stats(). Returns y_hat (dims.y x N*B),
  // valid until the next forward. Throws std::invalid_argument on shape errors
  // or a state index outside [0, dims.states).
  const Matrix<S>& forward(const HadynetParams<S>& params, const WindowBatch<S>& batch,
                           BnMode mode);

  // Back-propagates dL/dy_hat (dims.y x N*B) of the last forward. `params`
  // must hold the same values as in that forward. Overwrites `grads`
  // (resizing it as needed).
  //
  // Truncation depth K >= 1: the gradient of output y_hat_k flows back through
  // at most K LSTM steps, namely steps k, k-1, .., k-K+1; at the state
  // (h_{k-K+1}, c_{k-K+1}) it is dropped, i.e. that state is treated as a
  // constant (detached) for this output. The encoder output h_0 is not a
  // recurrent step: output k reaches the encoder (and x, and p through it)
  // iff k+1 <= K. Every other path (decoder, the LSTM input [u_j ; p] of a
  // step the gradient passes) is unaffected. K >= N is full BPTT (exact
  // gradient of L). K = 1 detaches h_k, c_k for every k >= 1.
  // Cost: full BPTT does one W_hh^T product per step; K < N keeps up to K-1
  // gradient streams alive, i.e. up to min(K, N) - 1 such products per step
  // (K = 1: none).
  void backward(const HadynetParams<S>& params, const Matrix<S>& d_y_hat, HadynetGrads<S>& grads,
                int truncation = kFullBptt);

  // Moves the running statistics towards the batch statistics of the last
  // kTrain forward, as PyTorch BatchNorm1d does:
  //   running_mean = (1 - m) running_mean + m * batch_mean
  //   running_var  = (1 - m) running_var  + m * batch_var * B / (B - 1)   (unbiased)
  // Throws std::logic_error if the last forward was not kTrain.
  void update_bn_running_stats(HadynetParams<S>& params, double momentum = kBnMomentum) const;

  const Matrix<S>& y_hat() const { return y_hat_; }
  // Encoder output h_0 and LSTM hidden states: hidden x ((N+1)*B), block k = h_k.
  const Matrix<S>& hidden_states() const { return h_; }
  // Cell states c_0 (= 0) .. c_N: hidden x ((N+1)*B), block k = c_k.
  const Matrix<S>& cell_states() const { return c_; }

 private:
  void forward_recurrence(const HadynetParams<S>& params, int b0, int nb);
  void backward_recurrence(const HadynetParams<S>& params, int truncation);
  void backward_recurrence_columns(const HadynetParams<S>& params, int truncation, int b0, int nb);
  void backward_encoder(const HadynetParams<S>& params, HadynetGrads<S>& grads);

  // Shape of the last forward.
  HadynetDims dims_{};
  int batch_ = 0;
  int steps_ = 0;
  BnMode mode_ = BnMode::kEval;
  bool explicit_pb_ = false;
  std::vector<int> state_;

  // Forward activations.
  Matrix<S> enc_in_;     // (x + pb) x B: [x0 ; p]
  Matrix<S> bn_xhat_;    // hidden x B: normalised encoder pre-activation
  Matrix<S> bn_out_;     // hidden x B: gamma * xhat + beta (before ReLU)
  Vector<S> bn_mean_;    // hidden: statistics used (batch in kTrain, running in kEval)
  Vector<S> bn_var_;     // hidden: biased batch variance / running variance
  Vector<S> bn_invstd_;  // hidden: 1 / sqrt(var + eps)
  Matrix<S> u_;          // u x (N*B): copy of the commands
  Matrix<S> gates_;      // 4*hidden x (N*B): activated gates i, f, g, o
  Matrix<S> c_;          // hidden x ((N+1)*B): cell states c_0 .. c_N
  Matrix<S> tanh_c_;     // hidden x (N*B): tanh(c_{k+1})
  Matrix<S> h_;          // hidden x ((N+1)*B): h_0 .. h_N
  Matrix<S> y_hat_;      // y x (N*B)
  Matrix<S> gates_pb_;   // 4*hidden x B: W_ih[:, u:] p + b_ih + b_hh (forward scratch)

  // Backward scratch.
  Matrix<S> d_h_out_;          // hidden x (N*B): W_dec^T dL/dy_hat
  Matrix<S> d_gates_;          // 4*hidden x (N*B): dL/d(gate pre-activations), all streams summed
  Matrix<S> d_h_in_;           // hidden x (S*B): dL/dh_{k+1} per live stream
  Matrix<S> d_c_in_;           // hidden x (S*B): dL/dc_{k+1} per live stream (from later steps)
  Matrix<S> d_c_total_;        // hidden x (S*B)
  Matrix<S> d_gates_streams_;  // 4*hidden x (S*B)
  Matrix<S> d_h0_;             // hidden x B: dL/dh_0
  Matrix<S> d_gates_pb_sum_;   // 4*hidden x B: sum over steps of d_gates (for the PB input)
};

extern template class HadynetNetwork<float>;
extern template class HadynetNetwork<double>;

}  // namespace hadynet::trainer
