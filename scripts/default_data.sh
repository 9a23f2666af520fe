# Sourced by run.sh and bench.sh (with $root set to the project folder): sets `inputs`, the
# folders the database is built from. The default data is the Bandai normal clips, plus the
# ReActIdle genuine idles where they exist (another skeleton: mm build retargets them, and the
# controller plays them when the character stands); $MM_DATA replaces both.
if [ -n "${MM_DATA:-}" ]; then
  inputs=("$MM_DATA")
else
  inputs=("$root/../shared/mocap/bandai-normal")
  if [ -d "$root/../shared/mocap/reactidle/genuine" ]; then
    inputs+=("$root/../shared/mocap/reactidle/genuine")
  fi
fi
