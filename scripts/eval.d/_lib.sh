# Shared helpers for the evaluations in scripts/eval.d (sourced, not run).

# sim_sequence SCENARIO [FRAMES] -> prints the sequence folder (generated once, cached).
# SIM_SEED=S (default 1) renders the same scenario (same geometry and motions) with other
# textures: the spread over seeds shows how much a figure owes to one rendering.
sim_sequence() {
  local scenario="$1" frames="${2:-300}" seed="${SIM_SEED:-1}"
  local dir="$MBSLAM_ROOT/out/sim_cache/${scenario}-${frames}"
  if [[ "$seed" != 1 ]]; then dir+="-seed$seed"; fi
  if [[ ! -f "$dir/sequence.lcmlog" ]]; then
    rm -rf "$dir"
    mkdir -p "$(dirname "$dir")"
    "$MBSLAM_BIN/mbslam-sim" --quiet --scenario "$scenario" --frames "$frames" --seed "$seed" --out "$dir" >&2
  fi
  echo "$dir"
}

# run_service INPUT_LOG RESULT_DIR [perception_service args...]
# Lockstep replay; writes RESULT_DIR/{out.lcmlog, result/, service.log}.
run_service() {
  local input="$1" result="$2"
  shift 2
  mkdir -p "$result"
  if ! "$MBSLAM_BIN/perception_service" --lcm-url "file://$input?speed=0" --mode lockstep \
    --output-log "$result/out.lcmlog" --output-dir "$result/result" "$@" 2>"$result/service.log"; then
    echo "perception_service failed; the end of $result/service.log:" >&2
    tail -20 "$result/service.log" >&2
    return 1
  fi
}

# path_length TUM_FILE -> metres along the trajectory
path_length() {
  awk '!/^#/ && NF >= 8 {if (n++) {dx=$2-x; dy=$3-y; dz=$4-z; L+=sqrt(dx*dx+dy*dy+dz*dz)} x=$2; y=$3; z=$4} END {printf "%.6f\n", L}' "$1"
}

# last_json CMD... -> runs CMD, echoes its output to stderr, prints its last line if it
# is a JSON object, else {} (a metric that could not be computed is reported as missing)
last_json() {
  local out line
  out=$("$@" 2>&1) || true
  echo "$out" >&2
  line=$(echo "$out" | tail -1)
  if [[ "$line" == "{"* ]]; then echo "$line"; else echo "{}"; fi
}

# json_get JSON KEY -> value (python3)
json_get() {
  python3 -c 'import json,sys; v=json.loads(sys.argv[1]).get(sys.argv[2]); print("null" if v is None else v)' "$1" "$2"
}

# tartanair_from START SRC DST [END]: DST holds SRC's images from START on (up to END,
# exclusive; default all), renumbered from 0 (symbolic links), and their truth lines.
tartanair_from() {
  local k="$1" src="$2" dst="$3" end="${4:-}"
  rm -rf "$dst"
  mkdir -p "$dst/images"
  local n i
  n=$(find "$src/images" -name '*_left.jpg' | wc -l)
  if [[ -n "$end" && "$end" -lt "$n" ]]; then n="$end"; fi
  for ((i = k; i < n; i++)); do
    ln -s "$src/images/$(printf %06d_left.jpg "$i")" "$dst/images/$(printf %06d_left.jpg $((i - k)))"
  done
  sed -n "$((k + 1)),${n}p" "$src/pose_left.txt" > "$dst/pose_left.txt"
}
