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
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <string>

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
    if (a == "--drop-frames" && need(4)) {
      const int n = editor.DropFrames(std::atof(argv[i + 1]), static_cast<uint32_t>(std::atol(argv[i + 4])),
                                      std::atoi(argv[i + 2]), std::atoi(argv[i + 3]));
      std::printf("dropped %d frames\n", n);
      i += 4;
    } else if (a == "--time-shift" && need(2)) {
      st = editor.ShiftTime(std::atoi(argv[i + 1]), std::atoll(argv[i + 2]));
      std::printf("time shifted by %s us from frame %s\n", argv[i + 2], argv[i + 1]);
      i += 2;
    } else if (a == "--drop-odometry" && need(2)) {
      std::printf("dropped %d odometry messages\n",
                  editor.DropOdometry(std::atoll(argv[i + 1]), std::atoll(argv[i + 2])));
      i += 2;
    } else if (a == "--corrupt-odometry" && need(3)) {
      const double v = SpecialValue(argv[i + 3], &ok);
      if (!ok) return Usage();
      std::printf("corrupted %d odometry messages\n",
                  editor.CorruptOdometry(std::atoll(argv[i + 1]), std::atoll(argv[i + 2]), v));
      i += 3;
    } else if (a == "--bad-calibration" && need(2)) {
      const double v = SpecialValue(argv[i + 2], &ok);
      if (!ok) return Usage();
      st = editor.InjectBadCalibration(std::atoi(argv[i + 1]), v);
      std::printf("bad calibration before frame %s\n", argv[i + 1]);
      i += 2;
    } else if (a == "--resize-frame" && need(3)) {
      st = editor.ResizeFrame(std::atoi(argv[i + 1]), std::atoi(argv[i + 2]), std::atoi(argv[i + 3]));
      std::printf("frame %s resized to %sx%s\n", argv[i + 1], argv[i + 2], argv[i + 3]);
      i += 3;
    } else if (a == "--burst" && need(3)) {
      st = editor.Burst(std::atoi(argv[i + 1]), std::atoi(argv[i + 2]), std::atof(argv[i + 3]));
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
