using System;
using System.Collections.Generic;
using System.Linq;
using System.Reflection;
using System.Runtime.CompilerServices;
using System.Runtime.InteropServices;
using System.Text.RegularExpressions;
using Xunit;

namespace Drape.Tests
{
    /// <summary>Version functions, and that Native.cs declares exactly the header's functions.</summary>
    public class VersionAndAbiTests
    {
        public VersionAndAbiTests() => TestEnvironment.RequireNativeLibrary();

        [Fact]
        public void NativeVersion_HasTheBindingsMajor_AndMatchesItsString()
        {
            DrapeVersion v = DrapeLibrary.Version;
            Assert.Equal(DrapeLibrary.ExpectedMajor, v.Major);
            Assert.Equal(Native.drape_version(), v.Packed);
            Assert.Equal(v.ToString(), DrapeLibrary.VersionString);
            DrapeLibrary.EnsureCompatible();  // does not throw
        }

        [Fact]
        public void BindingVersion_IsTheHeadersVersion()
        {
            string h = TestEnvironment.HeaderText;
            int Define(string name) => int.Parse(Regex.Match(h, @"#define\s+" + name + @"\s+(\d+)").Groups[1].Value);
            Assert.Equal(new DrapeVersion(Define("DRAPE_VERSION_MAJOR"), Define("DRAPE_VERSION_MINOR"), Define("DRAPE_VERSION_PATCH")),
                         DrapeLibrary.BindingVersion);
        }

        [Fact]
        public void PackedVersion_RoundTrips()
        {
            var v = new DrapeVersion(3, 1023, 4095);
            Assert.Equal((3u << 22) | (1023u << 12) | 4095u, v.Packed);
            Assert.Equal(v, DrapeVersion.FromPacked(v.Packed));
        }

        [Fact]
        public void CompatibilityCheck_RejectsAnotherMajor_AcceptsAnotherMinor()
        {
            uint otherMajor = new DrapeVersion(DrapeLibrary.ExpectedMajor + 1, 0, 0).Packed;
            var e = Assert.Throws<DrapeVersionMismatchException>(() => DrapeLibrary.CheckCompatible(otherMajor));
            Assert.Equal(DrapeLibrary.ExpectedMajor + 1, e.NativeVersion.Major);
            Assert.Contains($"major version {DrapeLibrary.ExpectedMajor}", e.Message);
            DrapeLibrary.CheckCompatible(new DrapeVersion(DrapeLibrary.ExpectedMajor, 77, 5).Packed);
        }

        [Fact]
        public void ResultNames_AreTheHeadersEnumeratorNames()
        {
            string h = TestEnvironment.HeaderText;
            foreach (ResultCode code in Enum.GetValues<ResultCode>())
            {
                string name = DrapeLibrary.ResultName(code);
                Assert.Matches(@"\b" + name + @"\s*=\s*" + (int)code + @"\b", h);
            }
            Assert.Equal("DRAPE_ERROR_UNKNOWN", DrapeLibrary.ResultName((ResultCode)999));
        }

        private static IEnumerable<(string Name, int ParamCount)> HeaderFunctions()
        {
            var rx = new Regex(@"DRAPE_API\s+[^;]*?DRAPE_CALL\s+(\w+)\s*\(([^)]*)\)\s*;", RegexOptions.Singleline);
            foreach (Match m in rx.Matches(TestEnvironment.HeaderText))
            {
                string args = m.Groups[2].Value.Trim();
                yield return (m.Groups[1].Value, args == "void" || args.Length == 0 ? 0 : args.Split(',').Length);
            }
        }

        private static MethodInfo[] Imports() =>
            typeof(Native).GetMethods(BindingFlags.Static | BindingFlags.NonPublic | BindingFlags.Public)
                .Where(m => m.GetCustomAttribute<DllImportAttribute>() != null).ToArray();

        [Fact]
        public void NativeCs_DeclaresEveryHeaderFunction_WithTheSameParameterCount()
        {
            var header = HeaderFunctions().ToDictionary(f => f.Name, f => f.ParamCount);
            Assert.True(header.Count >= 22, $"parsed only {header.Count} functions from drape.h");
            var imports = Imports().ToDictionary(m => m.GetCustomAttribute<DllImportAttribute>()!.EntryPoint ?? m.Name);
            Assert.Equal(header.Keys.OrderBy(k => k), imports.Keys.OrderBy(k => k));
            foreach (var (name, count) in header)
                Assert.True(imports[name].GetParameters().Length == count,
                            $"{name}: drape.h has {count} parameters, Native.cs {imports[name].GetParameters().Length}");
        }

        [Fact]
        public void EveryImport_IsCdecl_NamesTheLibrary_AndIsExported()
        {
            IntPtr lib = NativeLibrary.Load(TestEnvironment.NativePath);
            try
            {
                foreach (MethodInfo m in Imports())
                {
                    var a = m.GetCustomAttribute<DllImportAttribute>()!;
                    Assert.Equal(Native.LibraryName, a.Value);
                    Assert.Equal(CallingConvention.Cdecl, a.CallingConvention);
                    Assert.True(NativeLibrary.TryGetExport(lib, a.EntryPoint ?? m.Name, out _), $"{m.Name} is not exported");
                    // Blittable signatures only: nothing for the marshaller to convert.
                    foreach (Type t in m.GetParameters().Select(p => p.ParameterType).Append(m.ReturnType))
                        Assert.True(t.IsPointer || t == typeof(IntPtr) || t == typeof(UIntPtr) || t == typeof(uint) ||
                                    t == typeof(int) || t == typeof(void) || t == typeof(double) || t.IsEnum,
                                    $"{m.Name}: parameter type {t} is not a plain blittable type");
                }
            }
            finally
            {
                NativeLibrary.Free(lib);
            }
        }
    }

    /// <summary>The C# structs and enums mirror drape.h byte for byte.</summary>
    public class StructLayoutTests
    {
        private static unsafe int SizeOf<T>() where T : unmanaged => sizeof(T);

        private static void AssertLayout<T>(int expectedSize, params (string Field, int Offset)[] offsets) where T : unmanaged
        {
            Assert.False(RuntimeHelpers.IsReferenceOrContainsReferences<T>());
            Assert.Equal(expectedSize, SizeOf<T>());
            Assert.Equal(expectedSize, Marshal.SizeOf<T>());  // marshalled == managed: blittable
            FieldInfo[] fields = typeof(T).GetFields(BindingFlags.Instance | BindingFlags.Public | BindingFlags.NonPublic);
            Assert.Equal(offsets.Select(o => o.Field), fields.Select(f => f.Name));
            foreach (var (field, offset) in offsets)
                Assert.True(offset == (int)Marshal.OffsetOf<T>(field), $"{typeof(T).Name}.{field}: offset {Marshal.OffsetOf<T>(field)}, C has {offset}");
        }

        // Sizes: static_asserts at the end of native/src/capi/capi_context.cpp. Offsets: C layout rules.
        [Fact] public void Vec3_Is12() => AssertLayout<Vector3f>(12, ("X", 0), ("Y", 4), ("Z", 8));
        [Fact] public void Quat_Is16() => AssertLayout<Quaternionf>(16, ("X", 0), ("Y", 4), ("Z", 8), ("W", 12));
        [Fact] public void Joint_Is16() => AssertLayout<Joint>(16, ("Position", 0), ("TrackingState", 12));

        [Fact]
        public void ContextDesc_Is64() => AssertLayout<ContextDesc>(64,
            ("StructSize", 0), ("RingPoints", 4), ("RingsPerSegment", 8), ("CalibrationFrames", 12), ("Filter", 16),
            ("FilterMinCutoffHz", 20), ("FilterBeta", 24), ("FilterDCutoffHz", 28), ("Smoothing", 32), ("Correction", 36),
            ("Prediction", 40), ("JitterRadiusM", 44), ("MaxDeviationM", 48), ("TeleportDistanceM", 52),
            ("ProxyRule", 56), ("Reserved", 60));

        [Fact]
        public void BodyShape_Is48() => AssertLayout<BodyShape>(48,
            ("StructSize", 0), ("Sex", 4), ("HeightM", 8), ("WeightKg", 12), ("NeckMm", 16), ("ChestMm", 20),
            ("WaistMm", 24), ("HipMm", 28), ("ThighMm", 32), ("CalfMm", 36), ("UpperArmMm", 40), ("ForearmMm", 44));

        [Fact]
        public void SkeletonFrame_Is40On64Bit()
        {
            int p = IntPtr.Size;
            AssertLayout<SkeletonFrame>(24 + 2 * p,
                ("StructSize", 0), ("Layout", 4), ("JointCount", 8), ("Reserved", 12), ("TimestampS", 16),
                ("Joints", 24), ("Orientations", 24 + p));
            if (p == 8) Assert.Equal(40, SizeOf<SkeletonFrame>());
        }

        [Fact]
        public void FrameStats_Is72() => AssertLayout<FrameStats>(72,
            ("StructSize", 0), ("FramesPushed", 4), ("FramesAccepted", 8), ("FramesRejected", 12), ("FramesDropped", 16),
            ("Updates", 20), ("Teleports", 24), ("Teleported", 28), ("Calibrated", 29), ("Reserved0", 30),
            ("Reserved1", 31), ("LastTimestampS", 32), ("SkeletonMs", 40), ("BodyMs", 48), ("ProxiesMs", 56),
            ("BodyVolumeL", 64), ("Reserved2", 68));

        [Fact]
        public void Ellipsoid_Is68() => AssertLayout<Ellipsoid>(68,
            ("Centre", 0), ("AxisX", 12), ("AxisY", 24), ("AxisZ", 36), ("Radii", 48), ("Chain", 60), ("Ring", 64));

        [Fact]
        public void ProxyFidelity_Is40() => AssertLayout<ProxyFidelity>(40,
            ("StructSize", 0), ("UnionSamples", 4), ("BodyToProxyMeanMm", 8), ("BodyToProxyP95Mm", 12),
            ("BodyToProxyMaxMm", 16), ("ProxyToBodyMeanMm", 20), ("ProxyToBodyP95Mm", 24), ("ProxyToBodyMaxMm", 28),
            ("OutsideFraction", 32), ("Reserved", 36));

        [Fact]
        public void RecordingInfo_Is32() => AssertLayout<RecordingInfo>(32,
            ("StructSize", 0), ("Format", 4), ("Layout", 8), ("JointCount", 12), ("FrameCount", 16),
            ("NominalRateHz", 20), ("DurationS", 24));

        public static IEnumerable<object[]> Enums() => new[]
        {
            new object[] { "drape_result", typeof(ResultCode) },
            new object[] { "drape_layout", typeof(Layout) },
            new object[] { "drape_proxy_rule", typeof(ProxyRule) },
            new object[] { "drape_tracking_state", typeof(TrackingState) },
            new object[] { "drape_filter", typeof(Filter) },
            new object[] { "drape_sex", typeof(Sex) },
            new object[] { "drape_recording_format", typeof(RecordingFormat) },
        };

        /// <summary>Every enumerator of the C enum (but *_FORCE32) has the C# member whose name, upper-cased,
        /// ends its C name, with the same value; and the C# enum has no other member.</summary>
        [Theory]
        [MemberData(nameof(Enums))]
        public void Enum_MatchesTheHeader(string cName, Type csType)
        {
            Assert.Equal(typeof(int), Enum.GetUnderlyingType(csType));
            Match body = Regex.Match(TestEnvironment.HeaderText, @"typedef\s+enum\s+" + cName + @"\s*\{([^}]*)\}");
            Assert.True(body.Success, $"enum {cName} not found in drape.h");
            var c = Regex.Matches(body.Groups[1].Value, @"(DRAPE_\w+)\s*=\s*(\d+)")
                .Select(m => (Name: m.Groups[1].Value, Value: int.Parse(m.Groups[2].Value)))
                .Where(e => !e.Name.EndsWith("_FORCE32")).ToList();
            string[] cs = Enum.GetNames(csType);
            Assert.Equal(c.Count, cs.Length);
            foreach (var (name, value) in c)
            {
                string flat = name.Replace("_", "");
                string[] hits = cs.Where(n => flat.EndsWith(n.ToUpperInvariant())).ToArray();
                Assert.True(hits.Length >= 1, $"{name} has no C# member in {csType.Name}");
                string best = hits.OrderByDescending(n => n.Length).First();
                Assert.Equal(value, (int)Enum.Parse(csType, best));
            }
        }
    }
}
