#!/usr/bin/env bash
# Installs everything seep needs to build and test, from Debian 12 packages only.
# Run as root, or as a user with sudo rights (only apt-get runs with sudo).
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config git clang-format
  libgrpc++-dev libgrpc-dev protobuf-compiler-grpc libprotobuf-dev protobuf-compiler grpc-proto
  libeigen3-dev libspdlog-dev libfmt-dev libsqlite3-dev libsuitesparse-dev libopenblas-dev libssl-dev
  libgtest-dev libgmock-dev libbenchmark-dev libcli11-dev nlohmann-json3-dev openssl
  libcpp-httplib-dev  # seepd --metrics-listen: the Prometheus endpoint (and its test's client)
  python3-vtk9  # tests: exported .vtu/.vtp files load in VTK's own readers
  python3-grpcio python3-protobuf  # tests: a Python gRPC client (stubs made by protoc) drives seepd
  python3-numpy  # the Python package (client/python): results, series and fields as arrays
  python3-pandas python3-tqdm  # optional for the package (DataFrames, progress bar); CI tests them
  slurm-wlm munge  # tests (label slurm): seepd --executor slurm on a one-node cluster they start
)

sudo_cmd=()
if [ "$(id -u)" -ne 0 ]; then
  command -v sudo >/dev/null || { echo "install-deps: run as root or install sudo" >&2; exit 1; }
  sudo_cmd=(sudo)
fi

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages present"
  exit 0
fi
echo "install-deps: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
"${sudo_cmd[@]}" apt-get update -qq
"${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
echo "install-deps: done"
