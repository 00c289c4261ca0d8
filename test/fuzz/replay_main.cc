// The main() of a fuzz target built without libFuzzer (gcc): replays inputs and, with
// -runs=N, runs N deterministic mutations of them, so the default test suite runs
// every target over its seed corpus. The command line is libFuzzer's:
//
//   fuzz_TARGET [-runs=N] [-max_total_time=S] [-seed=K] [-artifact_prefix=P] [-x=..] PATH...
//
// PATH is a file or a folder (every regular file in it, sorted by name); the first
// folder is where libFuzzer would keep new inputs, here it is only read. Unknown -flags
// are ignored. A crash leaves the input that caused it in P + "crash-replay" (written
// from the signal handler) and ends the process as the crash would.

#include <fcntl.h>
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <random>
#include <string>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);

namespace {

// The input being run, for the crash handler (async-signal-safe use only).
const uint8_t* g_current = nullptr;
size_t g_current_size = 0;
char g_artifact_path[4096] = "crash-replay";
const char* g_current_name = "";

void OnCrash(int sig) {
  const int fd = open(g_artifact_path, O_WRONLY | O_CREAT | O_TRUNC, 0644);
  if (fd >= 0) {
    size_t done = 0;
    while (done < g_current_size) {
      const ssize_t n = write(fd, g_current + done, g_current_size - done);
      if (n <= 0) break;
      done += static_cast<size_t>(n);
    }
    close(fd);
  }
  const char msg[] = "\nfuzz replay: crash; input saved to ";
  (void)!write(2, msg, sizeof(msg) - 1);
  (void)!write(2, g_artifact_path, strlen(g_artifact_path));
  (void)!write(2, " (from ", 7);
  (void)!write(2, g_current_name, strlen(g_current_name));
  (void)!write(2, ")\n", 2);
  signal(sig, SIG_DFL);
  raise(sig);
}

void Run(const std::vector<uint8_t>& input, const char* name) {
  // A copy of exactly the input's size, so an overread lands outside the buffer.
  std::unique_ptr<uint8_t[]> copy(new uint8_t[std::max<size_t>(input.size(), 1)]);
  std::copy(input.begin(), input.end(), copy.get());
  g_current = copy.get();
  g_current_size = input.size();
  g_current_name = name;
  LLVMFuzzerTestOneInput(copy.get(), input.size());
  g_current = nullptr;
  g_current_size = 0;
}

bool ReadFile(const std::string& path, std::vector<uint8_t>* out) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return false;
  out->assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  return true;
}

// One random edit of the kinds that find decoder bugs: bit flips, byte values at the
// edges, 16/32-bit length fields set to extremes, truncation, splicing and insertion.
void Mutate(std::mt19937* rng, const std::vector<std::vector<uint8_t>>& pool,
            std::vector<uint8_t>* data) {
  auto pick = [rng](size_t n) { return n == 0 ? size_t{0} : static_cast<size_t>((*rng)() % n); };
  static const uint32_t kInteresting[] = {0u,          1u,          0x7fu,      0x80u,
                                          0xffu,       0x7fffu,     0x8000u,    0xffffu,
                                          0x7fffffffu, 0x80000000u, 0xffffffffu, 0x10000u};
  switch ((*rng)() % 8) {
    case 0:  // flip a bit
      if (!data->empty()) (*data)[pick(data->size())] ^= static_cast<uint8_t>(1u << ((*rng)() % 8));
      break;
    case 1:  // a random byte
      if (!data->empty()) (*data)[pick(data->size())] = static_cast<uint8_t>((*rng)());
      break;
    case 2:
    case 3: {  // an interesting 1/2/4-byte value, either byte order
      if (data->empty()) break;
      const uint32_t v = kInteresting[pick(std::size(kInteresting))];
      const size_t width = size_t{1} << pick(3);
      const size_t at = pick(data->size());
      const bool big_endian = (*rng)() & 1;
      for (size_t b = 0; b < width && at + b < data->size(); ++b) {
        const size_t shift = 8 * (big_endian ? width - 1 - b : b);
        (*data)[at + b] = static_cast<uint8_t>(v >> shift);
      }
      break;
    }
    case 4:  // truncate
      data->resize(pick(data->size() + 1));
      break;
    case 5: {  // erase a chunk
      if (data->empty()) break;
      const size_t at = pick(data->size());
      const size_t n = 1 + pick(std::min<size_t>(64, data->size() - at));
      data->erase(data->begin() + static_cast<long>(at), data->begin() + static_cast<long>(at + n));
      break;
    }
    case 6: {  // insert random bytes
      const size_t at = pick(data->size() + 1);
      const size_t n = 1 + pick(16);
      std::vector<uint8_t> bytes(n);
      for (uint8_t& b : bytes) b = static_cast<uint8_t>((*rng)());
      data->insert(data->begin() + static_cast<long>(at), bytes.begin(), bytes.end());
      break;
    }
    default: {  // splice in a piece of another input
      const std::vector<uint8_t>& other = pool[pick(pool.size())];
      if (other.empty()) break;
      const size_t from = pick(other.size());
      const size_t n = 1 + pick(std::min<size_t>(256, other.size() - from));
      const size_t at = pick(data->size() + 1);
      data->insert(data->begin() + static_cast<long>(at), other.begin() + static_cast<long>(from),
                   other.begin() + static_cast<long>(from + n));
      break;
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
  long runs = 0;
  double max_total_time = 0.0;
  unsigned seed = 1;
  std::string artifact_prefix;
  std::vector<std::string> paths;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a.rfind("-runs=", 0) == 0) runs = std::atol(a.c_str() + 6);
    else if (a.rfind("-max_total_time=", 0) == 0) max_total_time = std::atof(a.c_str() + 16);
    else if (a.rfind("-seed=", 0) == 0) seed = static_cast<unsigned>(std::atol(a.c_str() + 6));
    else if (a.rfind("-artifact_prefix=", 0) == 0) artifact_prefix = a.substr(17);
    else if (a.rfind("-", 0) == 0) continue;  // other libFuzzer flags
    else paths.push_back(a);
  }
  std::snprintf(g_artifact_path, sizeof(g_artifact_path), "%scrash-replay", artifact_prefix.c_str());
  for (int sig : {SIGSEGV, SIGABRT, SIGBUS, SIGFPE, SIGILL}) signal(sig, OnCrash);

  std::vector<std::string> files;
  for (const std::string& p : paths) {
    std::error_code ec;
    if (std::filesystem::is_directory(p, ec)) {
      std::vector<std::string> in_dir;
      for (const auto& e : std::filesystem::directory_iterator(p, ec)) {
        if (e.is_regular_file(ec)) in_dir.push_back(e.path().string());
      }
      std::sort(in_dir.begin(), in_dir.end());
      files.insert(files.end(), in_dir.begin(), in_dir.end());
    } else if (std::filesystem::is_regular_file(p, ec)) {
      files.push_back(p);
    } else {
      std::fprintf(stderr, "fuzz replay: no such file or folder: %s\n", p.c_str());
      return 1;
    }
  }

  const auto start = std::chrono::steady_clock::now();
  std::vector<std::vector<uint8_t>> pool;
  for (const std::string& f : files) {
    std::vector<uint8_t> data;
    if (!ReadFile(f, &data)) {
      std::fprintf(stderr, "fuzz replay: cannot read %s\n", f.c_str());
      return 1;
    }
    Run(data, f.c_str());
    pool.push_back(std::move(data));
  }
  if (pool.empty()) pool.emplace_back();

  std::mt19937 rng(seed);
  long done = 0;
  for (; done < runs; ++done) {
    if (max_total_time > 0.0 &&
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() >
            max_total_time) {
      break;
    }
    std::vector<uint8_t> data = pool[static_cast<size_t>(rng() % pool.size())];
    const int edits = 1 + static_cast<int>(rng() % 4);
    for (int e = 0; e < edits; ++e) Mutate(&rng, pool, &data);
    Run(data, "a mutation");
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf("fuzz replay: %zu inputs replayed, %ld mutations run, %.1f s, no crash\n",
              files.size(), done, seconds);
  return 0;
}
