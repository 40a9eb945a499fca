// libFuzzer target for the model-file reader (trainer/model_file.h): any
// bytes give a model that keeps the reader's promises (dims within
// trainer/model_limits.h, every stored number finite and within +-1e30,
// every std at least 1e-12) or a ModelFileError / safetensors FormatError.
// Another exception, a crash, a sanitizer report or an allocation past
// -rss_limit_mb is a finding.
//   build/release/fuzz/model_fuzzer -max_len=16384 WORKDIR fuzz/corpus/model
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "trainer/model_file.h"
#include "trainer/model_limits.h"
#include "trainer/safetensors.h"

namespace {

void require(bool ok) {
  if (!ok) std::abort();
}

template <class V>
void require_bounded(const V& v) {
  for (Eigen::Index i = 0; i < v.size(); ++i)
    require(std::abs(v.data()[i]) <= hadynet::trainer::ModelLimits::kMaxMagnitude);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace hadynet::trainer;
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  HadynetModel m;
  try {
    m = model_from_safetensors(safetensors::parse(bytes, "fuzz.safetensors"), "fuzz.safetensors");
  } catch (const ModelFileError& e) {
    require(e.what()[0] != '\0');
    return 0;
  } catch (const safetensors::FormatError& e) {
    require(e.what()[0] != '\0');
    return 0;
  }
  const HadynetDims& d = m.params.dims;
  require(d.y >= 1 && d.y <= ModelLimits::kMaxChannels && d.hidden >= 1 && d.hidden <= ModelLimits::kMaxHidden);
  require(m.train_steps >= 1 && m.train_steps <= ModelLimits::kMaxTrainSteps);
  for (const auto& t : m.params.tensors())
    for (int i = 0; i < t.size(); ++i) require(std::abs(t.data[i]) <= ModelLimits::kMaxMagnitude);
  for (const Eigen::VectorXd* s : {&m.norm.x.std, &m.norm.u.std, &m.norm.y.std})
    for (Eigen::Index i = 0; i < s->size(); ++i) require((*s)(i) >= ModelLimits::kMinStd);
  require_bounded(m.norm.x.mean);
  require_bounded(m.norm.y.mean);
  if (m.detection) require_bounded(m.detection->inverse);
  // An accepted model writes and reads back.
  const HadynetModel back = model_from_safetensors(model_to_safetensors(m), "again");
  require(back.params.dims == m.params.dims);
  return 0;
}
