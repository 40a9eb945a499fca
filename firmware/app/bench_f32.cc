// The benchmark image for the f32 model (bench.h; bench/qemu_icount.sh).
#include "boards/board.h"
#include "firmware/app/bench.h"
#include "firmware/core/hadynet_runtime.h"
#include "hadynet_model_f32.h"

namespace {

using Model = hadynet::model_f32::Model;
hadynet::firmware::HadynetRuntime<Model> g_runtime;
hadynet::firmware::HadynetNet<Model> g_net;

}  // namespace

int main() {
  hadynet::board::init();
  hadynet::app::Bench<Model>::run(g_runtime, g_net);
}
