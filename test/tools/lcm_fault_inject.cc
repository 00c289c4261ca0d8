// Rewrites an input LCM log with faults (see log_faults.h), applied in the order given:
//
//   lcm_fault_inject IN.lcmlog OUT.lcmlog [edits...]
//     --drop-frames FRACTION FIRST END SEED   drop frames in [FIRST, END) at random
//     --time-shift FRAME DELTA_US             step the clock of every input from FRAME on
//     --drop-odometry FROM_US TO_US           remove odometry in a message-time window
//     --corrupt-odometry FROM_US TO_US nan|inf
//     --bad-calibration FRAME nan|inf         insert a calibration with NaN / inf values
//     --resize-frame FRAME W H                one frame of another size
//     --burst FIRST COUNT FACTOR              hold frames back, then deliver at FACTOR x rate
//
// Prints one line per edit; exit 0 on success, 2 on bad arguments, 1 on I/O errors.

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <string>

#include "common/util/command_line.h"
#include "test/tools/log_faults.h"

namespace {

double SpecialValue(const std::string& s, bool* ok) {
  *ok = true;
  if (s == "nan") return std::numeric_limits<double>::quiet_NaN();
  if (s == "inf") return std::numeric_limits<double>::infinity();
  if (s == "-inf") return -std::numeric_limits<double>::infinity();
  *ok = false;
  return 0.0;
}

// One numeric argument of an edit, parsed whole (a malformed one is an error, not 0).
bool Int(const char* text, const char* what, int64_t* value) {
  const mbslam::Status s = mbslam::ParseInt64(text, what, value);
  if (!s.ok()) std::fprintf(stderr, "lcm_fault_inject: %s\n", s.message().c_str());
  return s.ok();
}
bool Int(const char* text, const char* what, int* value) {
  int64_t v = 0;
  if (!Int(text, what, &v)) return false;
  if (v < std::numeric_limits<int>::min() || v > std::numeric_limits<int>::max()) {
    std::fprintf(stderr, "lcm_fault_inject: %s: %s is out of range\n", what, text);
    return false;
  }
  *value = static_cast<int>(v);
  return true;
}
bool Real(const char* text, const char* what, double* value) {
  const mbslam::Status s = mbslam::ParseDouble(text, what, value);
  if (!s.ok()) std::fprintf(stderr, "lcm_fault_inject: %s\n", s.message().c_str());
  return s.ok();
}

int Usage() {
  std::fprintf(stderr,
               "usage: lcm_fault_inject IN.lcmlog OUT.lcmlog [--drop-frames F FIRST END SEED]\n"
               "  [--time-shift FRAME DELTA_US] [--drop-odometry FROM_US TO_US]\n"
               "  [--corrupt-odometry FROM_US TO_US nan|inf] [--bad-calibration FRAME nan|inf]\n"
               "  [--resize-frame FRAME W H] [--burst FIRST COUNT FACTOR]\n");
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) return Usage();
  mbslam::fault::LogEditor editor({});
  const mbslam::Status loaded = mbslam::fault::LogEditor::Load(argv[1], &editor);
  if (!loaded.ok()) {
    std::fprintf(stderr, "lcm_fault_inject: %s\n", loaded.message().c_str());
    return 1;
  }
  for (int i = 3; i < argc; ++i) {
    const std::string a = argv[i];
    auto need = [&](int n) { return i + n < argc; };
    mbslam::Status st;
    bool ok = true;
    int f1 = 0, f2 = 0, f3 = 0;  // frames, counts, sizes
    int64_t t1 = 0, t2 = 0;      // times, seeds
    double x = 0.0;
    if (a == "--drop-frames" && need(4)) {
      if (!Real(argv[i + 1], "--drop-frames FRACTION", &x) || !Int(argv[i + 2], "--drop-frames FIRST", &f1) ||
          !Int(argv[i + 3], "--drop-frames END", &f2) || !Int(argv[i + 4], "--drop-frames SEED", &t1)) {
        return Usage();
      }
      if (t1 < 0 || t1 > 0xffffffffLL) {
        std::fprintf(stderr, "lcm_fault_inject: --drop-frames SEED: %s is out of range (0-4294967295)\n", argv[i + 4]);
        return Usage();
      }
      const int n = editor.DropFrames(x, static_cast<uint32_t>(t1), f1, f2);
      std::printf("dropped %d frames\n", n);
      i += 4;
    } else if (a == "--time-shift" && need(2)) {
      if (!Int(argv[i + 1], "--time-shift FRAME", &f1) || !Int(argv[i + 2], "--time-shift DELTA_US", &t1)) {
        return Usage();
      }
      st = editor.ShiftTime(f1, t1);
      std::printf("time shifted by %s us from frame %s\n", argv[i + 2], argv[i + 1]);
      i += 2;
    } else if (a == "--drop-odometry" && need(2)) {
      if (!Int(argv[i + 1], "--drop-odometry FROM_US", &t1) || !Int(argv[i + 2], "--drop-odometry TO_US", &t2)) {
        return Usage();
      }
      std::printf("dropped %d odometry messages\n", editor.DropOdometry(t1, t2));
      i += 2;
    } else if (a == "--corrupt-odometry" && need(3)) {
      const double v = SpecialValue(argv[i + 3], &ok);
      if (!ok || !Int(argv[i + 1], "--corrupt-odometry FROM_US", &t1) ||
          !Int(argv[i + 2], "--corrupt-odometry TO_US", &t2)) {
        return Usage();
      }
      std::printf("corrupted %d odometry messages\n", editor.CorruptOdometry(t1, t2, v));
      i += 3;
    } else if (a == "--bad-calibration" && need(2)) {
      const double v = SpecialValue(argv[i + 2], &ok);
      if (!ok || !Int(argv[i + 1], "--bad-calibration FRAME", &f1)) return Usage();
      st = editor.InjectBadCalibration(f1, v);
      std::printf("bad calibration before frame %s\n", argv[i + 1]);
      i += 2;
    } else if (a == "--resize-frame" && need(3)) {
      if (!Int(argv[i + 1], "--resize-frame FRAME", &f1) || !Int(argv[i + 2], "--resize-frame W", &f2) ||
          !Int(argv[i + 3], "--resize-frame H", &f3)) {
        return Usage();
      }
      st = editor.ResizeFrame(f1, f2, f3);
      std::printf("frame %s resized to %sx%s\n", argv[i + 1], argv[i + 2], argv[i + 3]);
      i += 3;
    } else if (a == "--burst" && need(3)) {
      if (!Int(argv[i + 1], "--burst FIRST", &f1) || !Int(argv[i + 2], "--burst COUNT", &f2) ||
          !Real(argv[i + 3], "--burst FACTOR", &x)) {
        return Usage();
      }
      st = editor.Burst(f1, f2, x);
      std::printf("burst of %s frames at %sx from frame %s\n", argv[i + 2], argv[i + 3], argv[i + 1]);
      i += 3;
    } else {
      std::fprintf(stderr, "lcm_fault_inject: bad argument %s\n", a.c_str());
      return Usage();
    }
    if (!st.ok()) {
      std::fprintf(stderr, "lcm_fault_inject: %s\n", st.message().c_str());
      return 2;
    }
  }
  const mbslam::Status written = editor.Write(argv[2]);
  if (!written.ok()) {
    std::fprintf(stderr, "lcm_fault_inject: %s\n", written.message().c_str());
    return 1;
  }
  std::printf("wrote %s: %d frames, %zu events\n", argv[2], editor.num_frames(), editor.events().size());
  return 0;
}
