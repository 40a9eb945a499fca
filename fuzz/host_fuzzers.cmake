# libFuzzer targets for the host tools' readers (issue 19): the log reader,
# the dataset manifest and the model file. Included by fuzz/CMakeLists.txt
# after it found a clang that links -fsanitize=fuzzer (fuzz_sanitize).
# Host code: exceptions and RTTI on (the readers report errors by
# exception); compiled by custom commands calling clang++ directly, like
# the link fuzzers. Each runs 10 s in the suite from its seed corpus, and by
# hand for as long as wanted (docs/input-limits.md, "Fuzzing").

get_target_property(hadynet_fuzz_eigen_inc Eigen3::Eigen INTERFACE_INCLUDE_DIRECTORIES)
# (nlohmann_json's headers are in the system include path.)
set(host_fuzz_flags -std=c++20 -O2 -g -fno-omit-frame-pointer ${fuzz_sanitize}
    -I${PROJECT_SOURCE_DIR} -I${hadynet_fuzz_eigen_inc}
    -Wall -Wextra -Wno-unknown-pragmas)

# The log library's sources, as the build defines them (so a new file there
# needs no edit here).
hadynet_fuzz_collect_sources(hadynet_datalog fuzz_datalog_sources)
hadynet_fuzzer(log_fuzzer
  SOURCES "${CMAKE_CURRENT_SOURCE_DIR}/log_fuzzer.cc" ${fuzz_datalog_sources}
  FLAGS ${host_fuzz_flags}
  CORPUS "${CMAKE_CURRENT_SOURCE_DIR}/corpus/log" MAX_LEN 4096)
hadynet_fuzzer(manifest_fuzzer
  SOURCES "${CMAKE_CURRENT_SOURCE_DIR}/manifest_fuzzer.cc" ${fuzz_datalog_sources}
  FLAGS ${host_fuzz_flags}
  CORPUS "${CMAKE_CURRENT_SOURCE_DIR}/corpus/manifest" MAX_LEN 4096)
# The model reader and what it calls (found by linking; no Eigen kernels).
set(fuzz_model_sources "")
foreach(f model_file safetensors hadynet_params log_dataset sensor_model derived_inputs)
  list(APPEND fuzz_model_sources "${PROJECT_SOURCE_DIR}/trainer/${f}.cc")
endforeach()
hadynet_fuzzer(model_fuzzer
  SOURCES "${CMAKE_CURRENT_SOURCE_DIR}/model_fuzzer.cc" ${fuzz_datalog_sources} ${fuzz_model_sources}
  FLAGS ${host_fuzz_flags}
  CORPUS "${CMAKE_CURRENT_SOURCE_DIR}/corpus/model" MAX_LEN 16384)
