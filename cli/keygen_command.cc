// hadynet keygen: an Ed25519 key pair for signing model images
// (docs/model-update.md, "Keys").
#include <cstdio>

#include "cli/commands.h"
#include "cli/options.h"
#include "host-sim/model_image/signing_key.h"

namespace hadynet::cli {

int run_keygen(int argc, char** argv) {
  cli::Options opt("keygen",
                   "Makes an Ed25519 key pair for model images (libsodium): KEY holds the secret key\n"
                   "(mode 0600; keep it private: whoever has it can update every hand built with its\n"
                   "public half), KEY.pub the public key to build the firmware with\n"
                   "(-DHADYNET_MODEL_PUBLIC_KEY=KEY.pub). An existing KEY is never overwritten.\n"
                   "--development marks both files as a development key (the repository's\n"
                   "keys/development.key is one: its secret half is public).",
                   "--out KEY [--development]");
  opt.value("out", "KEY", "secret key file to write (KEY.pub is written next to it)");
  opt.flag("development", "mark the key as a development key in both files");
  if (!opt.parse(argc, argv)) return 2;
  if (opt.help_requested()) return 0;
  if (!opt.has("out") || !opt.positional().empty()) {
    std::fprintf(stderr, "hadynet keygen: give --out KEY and nothing else (see --help)\n");
    return 2;
  }
  try {
    const host::SigningKey key = host::generate_signing_key(opt.has("development"));
    host::write_signing_key(opt.get("out"), key);
    std::printf("%s: secret key%s\n%s.pub: public key %s\n", opt.get("out").c_str(),
                key.development ? " (marked DEVELOPMENT)" : "", opt.get("out").c_str(),
                host::hex(key.public_key).c_str());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "hadynet keygen: %s\n", e.what());
    return 1;
  }
  return 0;
}

}  // namespace hadynet::cli
