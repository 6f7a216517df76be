#!/usr/bin/env bash
# Assembles the Unity package com.drape.dressing (docs/unity.md) from its template in this folder:
#   Runtime/Drape/*.cs     the binding sources of bindings/csharp/Drape (compiled by Unity with
#                          Runtime/Drape.asmdef, so UNITY_IOS / UNITY_WEBGL switch to "__Internal")
#   Runtime/Unity/*.cs     Unity-only glue (from the template)
#   Plugins/Linux/x86_64/libdrape.so   the native library of this machine's build
#   Samples~/DressingFromRecording/    DrapeDresser + sensor sources + a real Kinect v2 recording
#   *.meta                 for every asset, with GUIDs derived from the path (stable across runs),
#                          so the package also works where Unity cannot write (git URL, tarball)
# Usage: bash bindings/csharp/unity/make-package.sh [--out DIR] [--native DIR] [--tgz] [--no-native]
#   --out DIR     where to put com.drape.dressing/ (default build/unity of the checkout)
#   --native DIR  folder with libdrape.so (default build/release/native)
#   --tgz         also write DIR/com.drape.dressing-VERSION.tgz (Package Manager: "Add package from tarball")
#   --no-native   leave Plugins/ empty (add the libraries by hand; docs/unity.md lists where)
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
root="$(cd "$here/../../.." && pwd)"
name="com.drape.dressing"
out="$root/build/unity"
native="$root/build/release/native"
tgz=0
with_native=1
while (($#)); do
  case "$1" in
    --out) out="$2"; shift 2 ;;
    --native) native="$2"; shift 2 ;;
    --tgz) tgz=1; shift ;;
    --no-native) with_native=0; shift ;;
    -h|--help) sed -n '2,17p' "${BASH_SOURCE[0]}"; exit 0 ;;
    *) echo "make-package.sh: unknown option '$1' (see --help)" >&2; exit 2 ;;
  esac
done

# The package version is the bindings' version (Drape.csproj), which is the C header's.
version="$(sed -n 's:.*"version"[[:space:]]*\:[[:space:]]*"\([^"]*\)".*:\1:p' "$here/$name/package.json" | head -1)"
csproj_version="$(sed -n 's:.*<Version>\(.*\)</Version>.*:\1:p' "$root/bindings/csharp/Drape/Drape.csproj" | head -1)"
if [[ "$version" != "$csproj_version" ]]; then
  echo "make-package.sh: package.json version '$version' differs from Drape.csproj's '$csproj_version'; make them equal" >&2
  exit 1
fi

mkdir -p "$out"
dest="$out/$name"
rm -rf "$dest"
cp -R "$here/$name" "$dest"

# Binding sources. Unity compiles without a nullable context: turn it on per file, as Drape.csproj does.
mkdir -p "$dest/Runtime/Drape"
for f in "$root"/bindings/csharp/Drape/*.cs; do
  { printf '#nullable enable\n'; cat "$f"; } > "$dest/Runtime/Drape/$(basename "$f")"
done

# Native library (the file behind the libdrape.so symlink chain).
if ((with_native)); then
  if [[ ! -e "$native/libdrape.so" ]]; then
    echo "make-package.sh: no $native/libdrape.so; build it (cmake --build --preset release --target drape)," \
         "pass --native DIR, or --no-native" >&2
    exit 1
  fi
  mkdir -p "$dest/Plugins/Linux/x86_64"
  cp -L "$native/libdrape.so" "$dest/Plugins/Linux/x86_64/libdrape.so"
fi

# The sample's recording and its licence.
cp "$root/samples/data/Ges01_wavehand.csv" "$root/samples/data/LICENSE_MIT_Microsoft.txt" \
   "$dest/Samples~/DressingFromRecording/"

# .meta files. Unity skips folders ending in '~' (Samples~ is copied into Assets/ on import and
# gets its .meta files there), so none are written inside it.
guid() { printf '%s' "$name/$1" | md5sum | cut -c1-32; }
tail_lines() {
  printf '  userData: \n  assetBundleName: \n  assetBundleVariant: \n'
}
write_meta() {  # $1 = path relative to $dest
  local rel="$1" path="$dest/$1" g
  g="$(guid "$rel")"
  {
    printf 'fileFormatVersion: 2\nguid: %s\n' "$g"
    if [[ -d "$path" ]]; then
      printf 'folderAsset: yes\nDefaultImporter:\n  externalObjects: {}\n'; tail_lines
    else
      case "$rel" in
        package.json)
          printf 'PackageManifestImporter:\n  externalObjects: {}\n'; tail_lines ;;
        *.cs)
          printf 'MonoImporter:\n  externalObjects: {}\n  serializedVersion: 2\n  defaultReferences: []\n'
          printf '  executionOrder: 0\n  icon: {instanceID: 0}\n'; tail_lines ;;
        *.asmdef)
          printf 'AssemblyDefinitionImporter:\n  externalObjects: {}\n'; tail_lines ;;
        Plugins/Linux/x86_64/*.so)
          # Editor and standalone player on Linux x86_64 only.
          cat <<'YAML'
PluginImporter:
  externalObjects: {}
  serializedVersion: 2
  iconMap: {}
  executionOrder: {}
  defineConstraints: []
  isPreloaded: 0
  isOverridable: 0
  isExplicitlyReferenced: 0
  validateReferences: 1
  platformData:
  - first:
      : Any
    second:
      enabled: 0
      settings:
        Exclude Editor: 0
        Exclude Linux64: 0
        Exclude OSXUniversal: 1
        Exclude Win: 1
        Exclude Win64: 1
  - first:
      Any: 
    second:
      enabled: 0
      settings: {}
  - first:
      Editor: Editor
    second:
      enabled: 1
      settings:
        CPU: x86_64
        DefaultValueInitialized: true
        OS: Linux
  - first:
      Standalone: Linux64
    second:
      enabled: 1
      settings:
        CPU: x86_64
  - first:
      Standalone: OSXUniversal
    second:
      enabled: 0
      settings:
        CPU: None
  - first:
      Standalone: Win
    second:
      enabled: 0
      settings:
        CPU: None
  - first:
      Standalone: Win64
    second:
      enabled: 0
      settings:
        CPU: None
YAML
          tail_lines ;;
        *.json|*.md|*.txt|*.csv)
          printf 'TextScriptImporter:\n  externalObjects: {}\n'; tail_lines ;;
        *)
          printf 'DefaultImporter:\n  externalObjects: {}\n'; tail_lines ;;
      esac
    fi
  } > "$path.meta"
}
while IFS= read -r -d '' p; do
  rel="${p#"$dest"/}"
  write_meta "$rel"
done < <(find "$dest" -mindepth 1 \( -name '*~' -prune \) -o \( ! -name '*.meta' -print0 \))

if ((tgz)); then
  # Package Manager tarballs hold the package under a top-level "package/" folder.
  tar -czf "$out/$name-$version.tgz" --owner=0 --group=0 --transform "s,^$name,package," -C "$out" "$name"
  echo "make-package.sh: $out/$name-$version.tgz"
fi
echo "make-package.sh: $dest (version $version)"
