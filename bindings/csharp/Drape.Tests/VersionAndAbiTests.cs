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
            foreach (ResultCode code in (ResultCode[])Enum.GetValues(typeof(ResultCode)))
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
                                    t == typeof(int) || t == typeof(void) || t == typeof(float) || t == typeof(double) ||
                                    t.IsEnum,
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
        public void ContextDesc_Is72() => AssertLayout<ContextDesc>(72,
            ("StructSize", 0), ("RingPoints", 4), ("RingsPerSegment", 8), ("CalibrationFrames", 12), ("Filter", 16),
            ("FilterMinCutoffHz", 20), ("FilterBeta", 24), ("FilterDCutoffHz", 28), ("Smoothing", 32), ("Correction", 36),
            ("Prediction", 40), ("JitterRadiusM", 44), ("MaxDeviationM", 48), ("TeleportDistanceM", 52),
            ("ProxyRule", 56), ("GarmentFit", 60), ("ArmsClearTorso", 64), ("ArmTorsoClearanceM", 68));

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
            ("Updates", 20), ("Teleports", 24), ("Teleported", 28), ("Calibrated", 29), ("PoseJumped", 30),
            ("Reserved1", 31), ("LastTimestampS", 32), ("SkeletonMs", 40), ("BodyMs", 48), ("ProxiesMs", 56),
            ("BodyVolumeL", 64), ("PoseJumps", 68));

        [Fact]
        public void Ellipsoid_Is68() => AssertLayout<Ellipsoid>(68,
            ("Centre", 0), ("AxisX", 12), ("AxisY", 24), ("AxisZ", 36), ("Radii", 48), ("Chain", 60), ("Ring", 64));

        [Fact]
        public void ProxyFidelity_Is40() => AssertLayout<ProxyFidelity>(40,
            ("StructSize", 0), ("UnionSamples", 4), ("BodyToProxyMeanMm", 8), ("BodyToProxyP95Mm", 12),
            ("BodyToProxyMaxMm", 16), ("ProxyToBodyMeanMm", 20), ("ProxyToBodyP95Mm", 24), ("ProxyToBodyMaxMm", 28),
            ("OutsideFraction", 32), ("Reserved", 36));

        // Garments: sizes asserted at the end of native/src/capi/capi_garments.cpp (but drape_cloth_params,
        // 136 bytes: C layout rules, checked with offsetof when this table was written).
        [Fact]
        public void GarmentDesc_Is24() => AssertLayout<GarmentDesc>(24,
            ("StructSize", 0), ("Solver", 4), ("AreaDensity", 8), ("MaxTethers", 12), ("DressTimeS", 16), ("Cut", 20));

        [Fact]
        public void GarmentTemplate_Is24() => AssertLayout<GarmentTemplate>(24,
            ("StructSize", 0), ("Kind", 4), ("Particles", 8), ("EaseM", 12), ("LengthScale", 16), ("Reserved", 20));

        [Fact]
        public void ClothParams_Is136() => AssertLayout<ClothParams>(136,
            ("StructSize", 0), ("SubstepHz", 4), ("MaxSubsteps", 8), ("MaxStepS", 12), ("Gravity", 16), ("Wind", 28),
            ("Drag", 40), ("Damping", 44), ("MaxSpeed", 48), ("StretchCompliance", 52), ("ShearCompliance", 56),
            ("BendCompliance", 60), ("TetherCompliance", 64), ("TetherScale", 68), ("StaticFriction", 72),
            ("KineticFriction", 76), ("CollisionMarginM", 80), ("ContactResponse", 84), ("ContinuousCollision", 88),
            ("LinearInertia", 92), ("AngularInertia", 96), ("BlendInS", 100), ("SpringStretch", 104),
            ("SpringShear", 108), ("SpringBend", 112), ("SpringDamping", 116), ("Iterations", 120), ("StrainLimit", 124),
            ("CollisionStride", 128), ("StrainLimitPasses", 132));

        [Fact]
        public void MeshFit_Is48() => AssertLayout<MeshFit>(48,
            ("StructSize", 0), ("UnitScale", 4), ("Facing", 8), ("SourceHeightM", 12), ("SourceWeightKg", 16),
            ("SourceFloorYM", 20), ("SourceAxisZM", 24), ("SourceArmDownDeg", 28), ("SourceElbowFlexDeg", 32),
            ("SourceLegSpreadDeg", 36), ("BlendM", 40), ("Reserved", 44));

        [Fact]
        public void GarmentStats_Is104() => AssertLayout<GarmentStats>(104,
            ("StructSize", 0), ("Particles", 4), ("Attached", 8), ("Substeps", 12), ("BlendFrames", 16), ("Contacts", 20),
            ("SweptCatches", 24), ("Escapes", 28), ("Steps", 32), ("TeleportReset", 40), ("NanReset", 41),
            ("Cut", 42), ("Reserved1", 43), ("Refits", 44), ("StepMs", 48), ("CollideMs", 56),
            ("IntegrateMs", 64), ("DeviceUploadMs", 72), ("DeviceKernelMs", 80), ("DeviceReadbackMs", 88),
            ("DeviceHostMs", 96));

        [Fact]
        public void GarmentAccuracy_Is44() => AssertLayout<GarmentAccuracy>(44,
            ("StructSize", 0), ("ProxyInside", 4), ("MaxStretch", 8), ("P99Stretch", 12), ("MeanStretch", 16),
            ("BodyPenetrationP99Mm", 20), ("BodyPenetrationMaxMm", 24), ("DeeperThan2mm", 28), ("Openings", 32),
            ("OpeningsOff", 36), ("InsideBody", 40));

        [Fact]
        public void RecordingInfo_Is32() => AssertLayout<RecordingInfo>(32,
            ("StructSize", 0), ("Format", 4), ("Layout", 8), ("JointCount", 12), ("FrameCount", 16),
            ("NominalRateHz", 20), ("DurationS", 24));

        // ---- Every struct of the header, laid out from its text ------------------------------------
        //
        // The tables above were written by hand; this test recomputes the layout of every
        // `typedef struct` in drape.h with the C rules (each field at the next multiple of its
        // alignment, the size rounded up to the largest alignment), so a field added to or moved in
        // the header fails here until the C# mirror follows.

        private static readonly Dictionary<string, Type> s_structs = new Dictionary<string, Type>
        {
            ["drape_vec3"] = typeof(Vector3f),
            ["drape_quat"] = typeof(Quaternionf),
            ["drape_joint"] = typeof(Joint),
            ["drape_context_desc"] = typeof(ContextDesc),
            ["drape_body_shape"] = typeof(BodyShape),
            ["drape_skeleton_frame"] = typeof(SkeletonFrame),
            ["drape_ellipsoid"] = typeof(Ellipsoid),
            ["drape_proxy_fidelity"] = typeof(ProxyFidelity),
            ["drape_frame_stats"] = typeof(FrameStats),
            ["drape_garment_desc"] = typeof(GarmentDesc),
            ["drape_garment_template"] = typeof(GarmentTemplate),
            ["drape_cloth_params"] = typeof(ClothParams),
            ["drape_mesh_fit"] = typeof(MeshFit),
            ["drape_garment_stats"] = typeof(GarmentStats),
            ["drape_garment_accuracy"] = typeof(GarmentAccuracy),
            ["drape_recording_info"] = typeof(RecordingInfo),
            ["drape_pipeline_options"] = typeof(PipelineOptions),
            ["drape_skip_stats"] = typeof(SkipStats),
            ["drape_backend_desc"] = typeof(BackendDesc),
            ["drape_backend_info"] = typeof(BackendInfo),
            ["drape_opencl_device"] = typeof(OpenClDeviceInfo),
        };

        private static Dictionary<string, string> HeaderStructBodies()
        {
            string h = Regex.Replace(TestEnvironment.HeaderText, @"/\*.*?\*/", " ", RegexOptions.Singleline);
            return Regex.Matches(h, @"typedef\s+struct\s+(\w+)\s*\{([^}]*)\}\s*\1\s*;")
                .ToDictionary(m => m.Groups[1].Value, m => m.Groups[2].Value);
        }

        /// <summary>(name, offset) of each field and the struct's size and alignment, by the C rules.</summary>
        private static (List<(string Name, int Offset)> Fields, int Size, int Align) CLayout(
            string body, Dictionary<string, string> all)
        {
            var fields = new List<(string, int)>();
            int offset = 0, maxAlign = 1;
            foreach (string decl in body.Split(';').Select(d => d.Trim()).Where(d => d.Length > 0))
            {
                Match m = Regex.Match(decl, @"^(?:const\s+)?(\w+)\s*(\**)\s*(.*)$", RegexOptions.Singleline);
                Assert.True(m.Success, $"cannot parse the declaration '{decl}'");
                string type = m.Groups[1].Value;
                bool pointer = m.Groups[2].Value.Length > 0;
                string[] names = m.Groups[3].Value.Split(',').Select(n => n.Trim()).ToArray();
                int size, align;
                if (pointer || names.Any(n => n.StartsWith("*")))
                {
                    size = align = IntPtr.Size;
                    names = names.Select(n => n.TrimStart('*', ' ')).ToArray();
                }
                else
                {
                    switch (type)
                    {
                        case "uint8_t": size = align = 1; break;
                        case "int32_t": case "uint32_t": case "float": size = align = 4; break;
                        case "uint64_t": case "double": size = align = 8; break;
                        default:
                            Assert.True(all.ContainsKey(type), $"unknown field type {type} in drape.h");
                            (_, size, align) = CLayout(all[type], all);
                            break;
                    }
                }
                foreach (string name in names)
                {
                    Assert.Matches(@"^\w+$", name);
                    offset = (offset + align - 1) / align * align;
                    fields.Add((name, offset));
                    offset += size;
                }
                maxAlign = Math.Max(maxAlign, align);
            }
            return (fields, (offset + maxAlign - 1) / maxAlign * maxAlign, maxAlign);
        }

        [Fact]
        public void EveryHeaderStruct_HasAMirror_WithTheSameFieldsOffsetsAndSize()
        {
            Dictionary<string, string> bodies = HeaderStructBodies();
            Assert.True(bodies.Count >= 16, $"parsed only {bodies.Count} structs from drape.h");
            Assert.Equal(bodies.Keys.OrderBy(k => k), s_structs.Keys.OrderBy(k => k));
            MethodInfo sizeOf = typeof(StructLayoutTests).GetMethod(nameof(SizeOf), BindingFlags.Static | BindingFlags.NonPublic)!;
            foreach (var (cName, body) in bodies)
            {
                Type cs = s_structs[cName];
                var (fields, size, _) = CLayout(body, bodies);
                FieldInfo[] csFields = cs.GetFields(BindingFlags.Instance | BindingFlags.Public | BindingFlags.NonPublic);
                Assert.True(fields.Count == csFields.Length,
                            $"{cName} has {fields.Count} fields, {cs.Name} {csFields.Length}");
                for (int i = 0; i < fields.Count; ++i)
                {
                    string c = fields[i].Name.Replace("_", "");
                    Assert.True(string.Equals(c, csFields[i].Name, StringComparison.OrdinalIgnoreCase),
                                $"{cName} field {i} is {fields[i].Name}, {cs.Name} has {csFields[i].Name}");
                    Assert.True(fields[i].Offset == (int)Marshal.OffsetOf(cs, csFields[i].Name),
                                $"{cName}.{fields[i].Name} at {fields[i].Offset}, {cs.Name}.{csFields[i].Name} at {Marshal.OffsetOf(cs, csFields[i].Name)}");
                }
                Assert.True(size == (int)sizeOf.MakeGenericMethod(cs).Invoke(null, null)!, $"{cName} is {size} bytes, {cs.Name} not");
                Assert.Equal(size, Marshal.SizeOf(cs));
            }
        }

        [Fact]
        public void EveryHeaderEnum_IsInTheEnumTable()
        {
            var header = Regex.Matches(TestEnvironment.HeaderText, @"typedef\s+enum\s+(\w+)").Select(m => m.Groups[1].Value);
            Assert.Equal(header.OrderBy(n => n), Enums().Select(e => (string)e[0]).OrderBy(n => n));
        }

        public static IEnumerable<object[]> Enums() => new[]
        {
            new object[] { "drape_result", typeof(ResultCode) },
            new object[] { "drape_layout", typeof(Layout) },
            new object[] { "drape_proxy_rule", typeof(ProxyRule) },
            new object[] { "drape_garment_fit", typeof(GarmentFit) },
            new object[] { "drape_garment_cut", typeof(GarmentCut) },
            new object[] { "drape_tracking_state", typeof(TrackingState) },
            new object[] { "drape_filter", typeof(Filter) },
            new object[] { "drape_sex", typeof(Sex) },
            new object[] { "drape_recording_format", typeof(RecordingFormat) },
            new object[] { "drape_garment_kind", typeof(GarmentKind) },
            new object[] { "drape_solver", typeof(Solver) },
            new object[] { "drape_contact_response", typeof(ContactResponse) },
            new object[] { "drape_mesh_facing", typeof(MeshFacing) },
            new object[] { "drape_pipeline_stage", typeof(PipelineStage) },
            new object[] { "drape_backend", typeof(Backend) },
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
