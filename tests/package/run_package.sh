#!/usr/bin/env bash
# The installed package as an integrator uses it: install the build to a prefix, move the prefix
# (installed executables must find share/navbus beside their bin directory, not in this source
# tree), build the two examples against it with find_package(navbus) and run them, and check the
# QoS file conventions with the installed executables.
# Usage: run_package.sh BUILD_DIR SOURCE_DIR DOMAIN   (DDS domains DOMAIN and DOMAIN+1)
set -euo pipefail
build=$1 src=$2 domain=$3
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }

cmake --install "$build" --prefix "$work/prefix" > "$work/install.log"
mv "$work/prefix" "$work/moved"
prefix=$work/moved
[[ -f $prefix/lib/cmake/navbus/navbusConfig.cmake && -f $prefix/lib/cmake/navbus/navbusConfigVersion.cmake ]] ||
  fail "no navbusConfig.cmake / navbusConfigVersion.cmake installed"
for f in share/navbus/qos/navbus_qos.xml share/navbus/config/filter.yaml \
  share/navbus/scenarios/seed000_aircraft.yaml share/doc/navbus/LICENSE \
  include/navbus/core/ins/strapdown.hpp include/navbus/nav_filter/filter_pipeline.hpp \
  include/navbus_idl/ImuPubSubTypes.h; do
  [[ -f $prefix/$f ]] || fail "$f not installed"
done

for example in engine embed_filter; do
  cmake -S "$src/examples/$example" -B "$work/$example" -DCMAKE_PREFIX_PATH="$prefix" \
    > "$work/$example.log" 2>&1 || { cat "$work/$example.log"; fail "configuring examples/$example"; }
  cmake --build "$work/$example" -j2 >> "$work/$example.log" 2>&1 ||
    { cat "$work/$example.log"; fail "building examples/$example"; }
done

echo "== examples/engine (navbus::core)"
"$work/engine/navbus_engine_example"
# The pure-math core brings neither DDS nor FFTW.
if ldd "$work/engine/navbus_engine_example" | grep -E "fftw|fastrtps|fastcdr"; then
  fail "navbus::core linked FFTW or Fast DDS"
fi

echo "== examples/embed_filter (navbus::filter in the user's own participant, domain $domain)"
"$work/embed_filter/navbus_embed_filter_example" "$domain"

echo "== installed executables read the moved prefix's share/navbus"
set +e
out=$("$prefix/bin/navbus" -d "$((domain + 1))" --profile no_such_profile topics --wait 0.1 2>&1)
rc=$?
set -e
[[ $rc == 3 ]] || fail "unknown profile: exit $rc, expected 3: $out"
grep -q "navbus's file '$prefix/share/navbus/qos/navbus_qos.xml'" <<< "$out" ||
  fail "the error does not name the installed QoS file: $out"
echo "$out" | tail -1

echo "== FASTRTPS_DEFAULT_PROFILES_FILE adds the user's profiles beside navbus's"
cat > "$work/my_profiles.xml" <<'XML'
<?xml version="1.0" encoding="UTF-8"?>
<dds xmlns="http://www.eprosima.com/XMLSchemas/fastRTPS_Profiles"><profiles>
  <participant profile_name="my_participant" is_default_profile="true"><rtps/></participant>
</profiles></dds>
XML
for profile in my_participant navbus_participant_udp_loopback; do
  FASTRTPS_DEFAULT_PROFILES_FILE=$work/my_profiles.xml \
    "$prefix/bin/navbus" -d "$((domain + 1))" --profile "$profile" topics --wait 0.1 > /dev/null ||
    fail "profile $profile with FASTRTPS_DEFAULT_PROFILES_FILE set: exit $?"
  echo "profile $profile: ok"
done
echo "package: ok"
