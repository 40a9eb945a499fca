// The digest that identifies a training dataset (the model file's provenance
// key "data_hash", docs/model-file.md).
#ifndef HADYNET_TRAINER_DATA_HASH_H_
#define HADYNET_TRAINER_DATA_HASH_H_

#include <string>
#include <vector>

namespace hadynet::trainer {

// SHA-256 (libsodium) over, per path in the given order, the file name (not
// the folder) with a terminating 0 byte, then the file's bytes: 64 lower-case
// hex digits. The same logs in the same order under another folder give the
// same digest; any changed byte, renamed file or other order another one.
// Throws std::runtime_error naming an unreadable file.
std::string data_hash(const std::vector<std::string>& paths);

}  // namespace hadynet::trainer

#endif  // HADYNET_TRAINER_DATA_HASH_H_
