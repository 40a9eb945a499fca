# libFuzzer targets for the host tools' readers (issue 19): the log reader,
# the dataset manifest and the model file. Included by fuzz/CMakeLists.txt
# after it found a clang that links -fsanitize=fuzzer (fuzz_sanitize).
# Host code: exceptions and RTTI on (the readers report errors by
# exception); compiled from the same sources as the host libraries, with
# the fuzzers' flags. Each runs 10 s in the suite from its seed corpus, and
# by hand for as long as wanted (docs/input-limits.md, "Fuzzing").

add_library(hadynet_fuzz_host_flags INTERFACE)
target_compile_options(hadynet_fuzz_host_flags INTERFACE -Wall -Wextra -Wno-unknown-pragmas)
target_link_libraries(hadynet_fuzz_host_flags INTERFACE hadynet_fuzz_sanitizers hadynet_eigen
  nlohmann_json::nlohmann_json)

# The log library's sources, as the build defines them (so a new file there
# needs no edit here), compiled once for the three fuzzers.
hadynet_fuzz_collect_sources(hadynet_datalog fuzz_datalog_sources)
add_library(hadynet_fuzz_datalog OBJECT ${fuzz_datalog_sources})
target_link_libraries(hadynet_fuzz_datalog PUBLIC hadynet_fuzz_host_flags)

hadynet_fuzzer(log_fuzzer
  SOURCES log_fuzzer.cc
  LIBRARIES hadynet_fuzz_datalog
  CORPUS "${CMAKE_CURRENT_SOURCE_DIR}/corpus/log" MAX_LEN 4096)
hadynet_fuzzer(manifest_fuzzer
  SOURCES manifest_fuzzer.cc
  LIBRARIES hadynet_fuzz_datalog
  CORPUS "${CMAKE_CURRENT_SOURCE_DIR}/corpus/manifest" MAX_LEN 4096)
# The model reader: the model-file library's sources, as the build defines
# them (trainer/CMakeLists.txt, hadynet_model_file; no trainer network).
get_target_property(fuzz_model_sources hadynet_model_file SOURCES)
list(TRANSFORM fuzz_model_sources PREPEND "${PROJECT_SOURCE_DIR}/trainer/")
hadynet_fuzzer(model_fuzzer
  SOURCES model_fuzzer.cc ${fuzz_model_sources}
  LIBRARIES hadynet_fuzz_datalog
  CORPUS "${CMAKE_CURRENT_SOURCE_DIR}/corpus/model" MAX_LEN 16384)
