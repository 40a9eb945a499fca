// The hadynet subcommands. Each takes the arguments after its name and
// returns the process exit code (0 ok, 1 failure, 2 usage error).
#pragma once

namespace hadynet::cli {

int run_collect(int argc, char** argv);
int run_validate(int argc, char** argv);
int run_import(int argc, char** argv);
int run_plot(int argc, char** argv);
int run_train(int argc, char** argv);
int run_adapt(int argc, char** argv);
int run_recognize(int argc, char** argv);
int run_calibrate_detect(int argc, char** argv);
int run_simulate(int argc, char** argv);
int run_detect(int argc, char** argv);
int run_replay(int argc, char** argv);
int run_link(int argc, char** argv);
int run_devices(int argc, char** argv);
int run_monitor(int argc, char** argv);
int run_flash(int argc, char** argv);
int run_stabilize(int argc, char** argv);
int run_measure_ranges(int argc, char** argv);
int run_codegen(int argc, char** argv);
int run_residual(int argc, char** argv);
int run_keygen(int argc, char** argv);
int run_model_image(int argc, char** argv);

}  // namespace hadynet::cli
