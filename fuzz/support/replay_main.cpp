/// @file replay_main.cpp
/// @brief Replay driver of a fuzz target for the normal (g++) build and CTest (label `fuzz`): runs
/// `LLVMFuzzerTestOneInput` over every file given (or every file in the folders given), then over
/// `--mutations N` deterministic mutants of them (seed `--seed S`). A finding aborts, as under
/// libFuzzer, so the test fails with the target's message; the mutant that failed is written to
/// `--save DIR` (default: the current folder) as `<driver>-mutant-<seed>-<index>` first, to be replayed
/// alone. Exit 2 on a usage error or when no input file is found (an empty corpus tests nothing).
///
///   fuzz_<target>_replay [--mutations N] [--seed S] [--save DIR] FILE|DIR...

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <string>
#include <vector>

#include "fuzz/support/fuzz_target.h"
#include "fuzz/support/mutator.h"

namespace fs = std::filesystem;

namespace {

std::string readFile(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

void run(const std::string& bytes) {
  LLVMFuzzerTestOneInput(reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size());
}

int usage(const char* argv0) {
  std::fprintf(stderr, "usage: %s [--mutations N] [--seed S] [--save DIR] FILE|DIR...\n", argv0);
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  long long mutations = 0;
  unsigned long long seed = 1;
  fs::path save_dir = ".";
  std::vector<fs::path> files;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if ((a == "--mutations" || a == "--seed" || a == "--save") && i + 1 < argc) {
      const std::string v = argv[++i];
      char* end = nullptr;
      if (a == "--save") {
        save_dir = v;
        continue;
      }
      const unsigned long long n = std::strtoull(v.c_str(), &end, 10);
      if (v.empty() || *end != '\0') return usage(argv[0]);
      if (a == "--mutations") mutations = static_cast<long long>(n);
      else seed = n;
    } else if (!a.empty() && a[0] == '-') {
      return usage(argv[0]);
    } else if (fs::is_directory(a)) {
      for (const auto& e : fs::directory_iterator(a))
        if (e.is_regular_file()) files.push_back(e.path());
    } else if (fs::is_regular_file(a)) {
      files.emplace_back(a);
    } else {
      std::fprintf(stderr, "%s: no such file or folder\n", a.c_str());
      return 2;
    }
  }
  if (files.empty()) {
    std::fprintf(stderr, "%s: no input files (an empty corpus tests nothing)\n", argv[0]);
    return 2;
  }
  std::sort(files.begin(), files.end());  // directory order differs between file systems
  std::vector<std::string> corpus;
  for (const auto& f : files) {
    corpus.push_back(readFile(f));
    run(corpus.back());
  }
  // The driver's name (fuzz_<target>_replay) keeps the reproducers of parallel tests apart.
  const std::string name = fs::path(argv[0]).filename().string();
  meshnav::fuzz::Mutator mutator(seed);
  std::mt19937_64 pick(seed ^ 0x9e3779b97f4a7c15ULL);
  for (long long k = 0; k < mutations; ++k) {
    const std::string& base = corpus[pick() % corpus.size()];
    const std::string& other = corpus[pick() % corpus.size()];
    const std::string mutant = mutator.mutate(base, other);
    // Written before the run so that an abort leaves the reproducer behind; removed after.
    const fs::path keep = save_dir / (name + "-mutant-" + std::to_string(seed) + "-" + std::to_string(k));
    { std::ofstream(keep, std::ios::binary) << mutant; }
    run(mutant);
    fs::remove(keep);
  }
  std::printf("%zu corpus files and %lld mutants (seed %llu): no finding\n", files.size(), mutations, seed);
  return 0;
}
