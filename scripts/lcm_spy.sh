#!/usr/bin/env bash
# lcm-spy with meshnav's message types (decodes every channel of docs/channels.md live).
# Debian's lcm-spy script passes -Xincgc, which Java >= 9 rejects; this starts the same class
# without it, with jchart2d (Debian package libjchart2d-java) and meshnav_lcmtypes.jar.
#
#   scripts/lcm_spy.sh [--jar FILE] [--lcm-url URL]
#
#   --jar FILE      meshnav_lcmtypes.jar (default: $MESHNAV_LCMTYPES_JAR, else
#                   <repo>/build/lcmtypes/meshnav_lcmtypes.jar)
#   --lcm-url URL   LCM provider (default: $LCM_DEFAULT_URL, else LCM's default)
#   --check         only check that java, lcm.jar, jchart2d and the types jar are present
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
jar=${MESHNAV_LCMTYPES_JAR:-$here/build/lcmtypes/meshnav_lcmtypes.jar}
url=${LCM_DEFAULT_URL:-}
check=0
while (( $# )); do
  case $1 in
    --jar) jar=$2; shift 2 ;;
    --lcm-url) url=$2; shift 2 ;;
    --check) check=1; shift ;;
    -h|--help) sed -n '2,13p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "lcm_spy.sh: unknown argument $1" >&2; exit 2 ;;
  esac
done
missing=()
command -v java > /dev/null || missing+=("java (apt-get install default-jre)")
[[ -f /usr/share/java/lcm.jar ]] || missing+=("/usr/share/java/lcm.jar (apt-get install liblcm-java)")
[[ -f /usr/share/java/jchart2d.jar ]] || missing+=("/usr/share/java/jchart2d.jar (apt-get install libjchart2d-java)")
[[ -f $jar ]] || missing+=("$jar (build the target meshnav_lcmtypes_jar)")
if (( ${#missing[@]} )); then
  printf 'lcm_spy.sh: missing %s\n' "${missing[@]}" >&2
  exit 1
fi
cp="/usr/share/java/lcm.jar:/usr/share/java/jchart2d.jar:$jar"
if (( check )); then
  # The spy finds the types by scanning its class path: make sure they load.
  java -cp "$cp" -Djava.awt.headless=true lcm.spy.Spy --help > /dev/null 2>&1 || true
  javap -cp "$cp" meshnav.pose_t > /dev/null
  echo "lcm_spy.sh: ok ($jar)"
  exit 0
fi
args=()
[[ -n $url ]] && args+=(--lcm-url "$url")
export CLASSPATH=$cp
exec java -server -Djava.net.preferIPv4Stack=true -Xmx256m -Xms64m -ea -cp "$cp" lcm.spy.Spy "${args[@]}"
