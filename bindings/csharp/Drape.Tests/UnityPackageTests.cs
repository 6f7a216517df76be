using System;
using System.Collections.Generic;
using System.IO;
using System.Linq;
using System.Reflection;
#if !DRAPE_MONO
using System.Text.Json;   // not in .NET Standard 2.1: the layout test is left out of the Mono build
#endif
using System.Text.RegularExpressions;
using Drape.Samples;
using UnityEngine;
using Xunit;
using Xunit.Abstractions;
using Vector3 = UnityEngine.Vector3;

namespace Drape.Tests
{
    /// <summary>
    /// The Unity package: its layout as make-package.sh assembles it, and its Unity-only scripts
    /// (compiled by Drape.UnityCheck against stand-ins of the UnityEngine and sensor SDK types)
    /// run here: DrapeDresser updates its Meshes every frame without allocating, the sensor sources
    /// map their SDK's joints onto Drape's layouts.
    /// </summary>
    public class UnityPackageTests
    {
        private readonly ITestOutputHelper _output;

        public UnityPackageTests(ITestOutputHelper output)
        {
            _output = output;
            TestEnvironment.RequireNativeLibrary();
        }

        private static string UnityDir => Path.Combine(TestEnvironment.RepoRoot, "bindings", "csharp", "unity");

        // ---- Layout ------------------------------------------------------------------------------
#if !DRAPE_MONO
        [Fact]
        public void MakePackage_AssemblesAValidPackage()
        {
            string? bash = TestProcess.FindOnPath("bash");
            if (bash == null || !OperatingSystem.IsLinux())
            {
                _output.WriteLine("SKIPPED: make-package.sh needs bash (checked on Linux)");
                return;
            }
            using var tmp = new TestProcess.TempDir("drape-unity");
            TestProcess.Result r = TestProcess.Run(bash, new[]
            {
                Path.Combine(UnityDir, "make-package.sh"), "--out", tmp.Path, "--native", TestEnvironment.NativeDir, "--tgz",
            });
            _output.WriteLine(r.Output);
            Assert.True(r.ExitCode == 0, $"make-package.sh failed: {r}");
            string pkg = Path.Combine(tmp.Path, "com.drape.dressing");
            string version = DrapeLibrary.BindingVersion.ToString();

            // package.json: Unity's required fields; its version is the bindings' (the header's).
            using (JsonDocument json = JsonDocument.Parse(File.ReadAllText(Path.Combine(pkg, "package.json"))))
            {
                JsonElement root = json.RootElement;
                Assert.Equal("com.drape.dressing", root.GetProperty("name").GetString());
                Assert.Equal(version, root.GetProperty("version").GetString());
                Assert.Matches(@"^20\d\d\.\d$", root.GetProperty("unity").GetString());
                JsonElement sample = root.GetProperty("samples")[0];
                Assert.True(Directory.Exists(Path.Combine(pkg, sample.GetProperty("path").GetString()!)));
            }
            // The asmdef: assembly "Drape", unsafe code on (the bindings use pointers).
            using (JsonDocument asmdef = JsonDocument.Parse(File.ReadAllText(Path.Combine(pkg, "Runtime", "Drape.asmdef"))))
            {
                Assert.Equal("Drape", asmdef.RootElement.GetProperty("name").GetString());
                Assert.True(asmdef.RootElement.GetProperty("allowUnsafeCode").GetBoolean());
            }

            // Every binding source is in Runtime/Drape, with a nullable context (Unity has none by default).
            string sources = Path.Combine(TestEnvironment.RepoRoot, "bindings", "csharp", "Drape");
            foreach (string cs in Directory.GetFiles(sources, "*.cs"))
            {
                string copy = Path.Combine(pkg, "Runtime", "Drape", Path.GetFileName(cs));
                Assert.True(File.Exists(copy), $"{Path.GetFileName(cs)} is missing from Runtime/Drape");
                Assert.Equal("#nullable enable\n" + File.ReadAllText(cs), File.ReadAllText(copy));
            }
            // Unity-only scripts use UnityEngine; the library's sources must not (netstandard2.1 without Unity).
            foreach (string cs in Directory.GetFiles(Path.Combine(pkg, "Runtime", "Unity"), "*.cs"))
                Assert.Contains("using UnityEngine;", File.ReadAllText(cs));
            foreach (string cs in Directory.GetFiles(sources, "*.cs"))
                Assert.DoesNotMatch(@"using\s+UnityEngine", File.ReadAllText(cs));

            // The native library and the sample's files.
            Assert.Equal(File.ReadAllBytes(Path.Combine(TestEnvironment.NativeDir, "libdrape.so")),
                         File.ReadAllBytes(Path.Combine(pkg, "Plugins", "Linux", "x86_64", "libdrape.so")));
            string meta = File.ReadAllText(Path.Combine(pkg, "Plugins", "Linux", "x86_64", "libdrape.so.meta"));
            Assert.Contains("PluginImporter:", meta);
            Assert.Contains("Standalone: Linux64", meta);
            string sampleDir = Path.Combine(pkg, "Samples~", "DressingFromRecording");
            foreach (string f in new[] { "DrapeDresser.cs", "KinectV2JointSourceBehaviour.cs", "AzureKinectJointSource.cs",
                                         "Ges01_wavehand.csv", "LICENSE_MIT_Microsoft.txt" })
                Assert.True(File.Exists(Path.Combine(sampleDir, f)), $"Samples~/DressingFromRecording/{f} is missing");

            // A .meta beside every asset outside Samples~ (immutable packages need them), unique GUIDs.
            var guids = new Dictionary<string, string>();
            foreach (string entry in Directory.EnumerateFileSystemEntries(pkg, "*", SearchOption.AllDirectories))
            {
                string rel = Path.GetRelativePath(pkg, entry);
                if (rel.StartsWith("Samples~", StringComparison.Ordinal) || rel.EndsWith(".meta", StringComparison.Ordinal)) continue;
                string metaPath = entry + ".meta";
                Assert.True(File.Exists(metaPath), $"{rel} has no .meta");
                Match m = Regex.Match(File.ReadAllText(metaPath), @"^guid: ([0-9a-f]{32})$", RegexOptions.Multiline);
                Assert.True(m.Success, $"{rel}.meta has no guid");
                Assert.False(guids.ContainsKey(m.Groups[1].Value), $"{rel} and {guids.GetValueOrDefault(m.Groups[1].Value)} share a GUID");
                guids[m.Groups[1].Value] = rel;
            }
            Assert.DoesNotContain(Directory.EnumerateFiles(sampleDir), f => f.EndsWith(".meta", StringComparison.Ordinal));

            // The tarball holds the same tree under package/.
            string tgz = Path.Combine(tmp.Path, $"com.drape.dressing-{version}.tgz");
            Assert.True(File.Exists(tgz));
            TestProcess.Result list = TestProcess.Run("tar", new[] { "-tzf", tgz });
            Assert.Equal(0, list.ExitCode);
            Assert.Contains("package/package.json", list.Output);
            Assert.Contains("package/Runtime/Drape/Context.cs", list.Output);
            Assert.Contains("package/Plugins/Linux/x86_64/libdrape.so", list.Output);
        }
#endif

        // ---- DrapeDresser on the stand-ins --------------------------------------------------------

        private static void Set(object target, string field, object? value)
        {
            FieldInfo f = target.GetType().GetField(field, BindingFlags.Instance | BindingFlags.NonPublic | BindingFlags.Public)
                          ?? throw new MissingFieldException(target.GetType().Name, field);
            f.SetValue(target, value);
        }

        private static void Message(object target, string method) =>
            (target.GetType().GetMethod(method, BindingFlags.Instance | BindingFlags.NonPublic | BindingFlags.Public)
             ?? throw new MissingMethodException(target.GetType().Name, method)).Invoke(target, null);

        [Fact]
        public void DrapeDresser_CutForTheSkeleton_IsCutAgainOnceCalibrated()
        {
            var refits = new System.Collections.Generic.List<uint>();
            foreach (GarmentCut cut in new[] { GarmentCut.Context, GarmentCut.Skeleton })
            {
                var go = new GameObject("person");
                var source = go.AddComponent<RecordingJointSourceBehaviour>();
                Set(source, "recording", new TextAsset(SyntheticKinect2.Csv(90)));
                MeshFilter garmentFilter = go.AddComponent<MeshFilter>();
                var dresser = go.AddComponent<DrapeDresser>();
                Set(dresser, "garment", GarmentKind.Trousers);
                Set(dresser, "particles", 400);
                Set(dresser, "cut", cut);
                Set(dresser, "garmentMesh", garmentFilter);
                Message(dresser, "OnEnable");
                Assert.True(dresser.enabled, string.Join("\n", UnityEngine.Debug.StandInLog));
                Time.deltaTime = 1f / 30f;
                for (int i = 0; i < 50; ++i) Message(dresser, "Update");  // cut for the first pose (or at 30, recut by 39)
                Assert.True(dresser.Loop.FramesAccepted >= 31, $"{dresser.Loop.FramesAccepted} frames accepted");
                refits.Add(dresser.Garment.Stats.Refits);
                Message(dresser, "OnDisable");
            }
            // The default context cuts for the shape: only the garment cut for the skeleton is cut again.
            Assert.Equal(new uint[] { 0, 1 }, refits);
        }

        [Fact]
        public void DrapeDresser_GarmentUnder_IsLayeredAndUpdatedEveryFrame()
        {
            var go = new GameObject("person");
            var source = go.AddComponent<RecordingJointSourceBehaviour>();
            Set(source, "recording", new TextAsset(SyntheticKinect2.Csv(30)));
            MeshFilter shirtFilter = go.AddComponent<MeshFilter>();
            var underGo = new GameObject("trousers");
            MeshFilter underFilter = underGo.AddComponent<MeshFilter>();
            var dresser = go.AddComponent<DrapeDresser>();
            Set(dresser, "particles", 400);
            Set(dresser, "garmentMesh", shirtFilter);
            Set(dresser, "underMesh", underFilter);
            Message(dresser, "OnEnable");
            Assert.True(dresser.enabled, string.Join("\n", UnityEngine.Debug.StandInLog));
            Assert.NotNull(dresser.UnderGarment);
            Assert.Equal(1, dresser.UnderGarment.Layer);
            Assert.Equal(2, dresser.Garment.Layer);
            Mesh under = underFilter.sharedMesh!;
            Assert.Equal(dresser.UnderGarment.IndexCount, under.StandInTriangles!.Length);
            Time.deltaTime = 1f / 30f;
            for (int i = 0; i < 10; ++i) Message(dresser, "Update");
            Assert.Equal(1 + 10, under.StandInVertexWrites);
            // What the Mesh got is the trousers, in Unity's space (x negated).
            var raw = new Vector3f[dresser.UnderGarment.VertexCount];
            dresser.UnderGarment.ReadPositions(raw);
            Vector3[] v = under.StandInVertices!;
            for (int i = 0; i < raw.Length; ++i) Assert.Equal(-raw[i].X, v[i].x);
            Message(dresser, "OnDisable");
            Assert.Null(dresser.UnderGarment);
        }

        [Fact]
        public void DrapeDresser_LessStretch_ReachesBothGarmentsParams()
        {
            ClothParams ParamsOf(bool less, bool under)
            {
                var go = new GameObject("person");
                var source = go.AddComponent<RecordingJointSourceBehaviour>();
                Set(source, "recording", new TextAsset(SyntheticKinect2.Csv(30)));
                var dresser = go.AddComponent<DrapeDresser>();
                Set(dresser, "particles", 300);
                Set(dresser, "garmentMesh", go.AddComponent<MeshFilter>());
                Set(dresser, "underMesh", new GameObject("trousers").AddComponent<MeshFilter>());
                if (less) Set(dresser, "lessStretch", true);
                Message(dresser, "OnEnable");
                Assert.True(dresser.enabled, string.Join("\n", UnityEngine.Debug.StandInLog));
                Time.deltaTime = 1f / 30f;
                for (int i = 0; i < 3; ++i) Message(dresser, "Update");
                ClothParams p = under ? dresser.UnderGarment!.Params : dresser.Garment!.Params;
                Message(dresser, "OnDisable");
                return p;
            }
            foreach (bool under in new[] { false, true })
            {
                ClothParams byDefault = ParamsOf(false, under), less = ParamsOf(true, under);
                Assert.Equal(2u, byDefault.StrainLimitPasses);
                Assert.Equal(0.1f, byDefault.StrainLimit, 1e-6f);
                Assert.Equal(8u, less.StrainLimitPasses);
                Assert.Equal(0.05f, less.StrainLimit, 1e-6f);
            }
        }

        [Fact]
        public void DrapeDresser_ArmsClearTorso_ReachesTheContext()
        {
            Vector3[] BodyAfterUpdates(bool armsClear)
            {
                var go = new GameObject("person");
                var source = go.AddComponent<RecordingJointSourceBehaviour>();
                Set(source, "recording", new TextAsset(SyntheticKinect2.Csv(30)));
                var bodyGo = new GameObject("body");
                MeshFilter bodyFilter = bodyGo.AddComponent<MeshFilter>();
                var dresser = go.AddComponent<DrapeDresser>();
                Set(dresser, "particles", 300);
                Set(dresser, "garmentMesh", go.AddComponent<MeshFilter>());
                Set(dresser, "bodyMesh", bodyFilter);
                if (!armsClear) Set(dresser, "armsClearTorso", false);
                Message(dresser, "OnEnable");
                Assert.True(dresser.enabled, string.Join("\n", UnityEngine.Debug.StandInLog));
                Time.deltaTime = 1f / 30f;
                for (int i = 0; i < 5; ++i) Message(dresser, "Update");
                Vector3[] v = (Vector3[])bodyFilter.sharedMesh!.StandInVertices!.Clone();
                Message(dresser, "OnDisable");
                return v;
            }
            Vector3[] clear = BodyAfterUpdates(true), onBones = BodyAfterUpdates(false);
            Assert.Equal(clear.Length, onBones.Length);
            float moved = 0f;
            for (int i = 0; i < clear.Length; ++i)
            {
                float dx = clear[i].x - onBones[i].x, dy = clear[i].y - onBones[i].y, dz = clear[i].z - onBones[i].z;
                moved = MathF.Max(moved, MathF.Sqrt(dx * dx + dy * dy + dz * dz));
            }
            // The synthetic person's arms hang against the torso: with the default some arm vertex
            // sits off where the rings on the bones put it.
            Assert.True(moved > 0.002f, $"largest body vertex difference {moved} m");
        }

        [Fact]
        public void DrapeDresser_UpdatesGarmentAndBodyMeshesEveryFrame_WithoutAllocating()
        {
            var go = new GameObject("person");
            var source = go.AddComponent<RecordingJointSourceBehaviour>();
            Set(source, "recording", new TextAsset(SyntheticKinect2.Csv(90)));
            MeshFilter garmentFilter = go.AddComponent<MeshFilter>();
            var bodyGo = new GameObject("body");
            MeshFilter bodyFilter = bodyGo.AddComponent<MeshFilter>();
            var dresser = go.AddComponent<DrapeDresser>();
            Set(dresser, "particles", 500);
            Set(dresser, "garmentMesh", garmentFilter);
            Set(dresser, "bodyMesh", bodyFilter);
            // jointSource left empty: the dresser finds the IJointSource on its GameObject.

            Message(dresser, "OnEnable");
            Assert.True(dresser.enabled, string.Join("\n", UnityEngine.Debug.StandInLog));
            Mesh garment = garmentFilter.sharedMesh!;
            Mesh body = bodyFilter.sharedMesh!;
            Assert.NotNull(garment);
            Assert.NotNull(body);
            Assert.Equal(UnityEngine.Rendering.IndexFormat.UInt32, garment.indexFormat);
            Assert.True(garment.StandInDynamic);
            Assert.Equal(dresser.Garment.IndexCount, garment.StandInTriangles!.Length);

            Time.deltaTime = 1f / 60f;
            for (int i = 0; i < 30; ++i) Message(dresser, "Update");
            // Once in OnEnable (CreateDynamicMesh), then every frame (the first frame is due at once).
            Assert.Equal(1 + 30, garment.StandInVertexWrites);
            Assert.Equal(1 + 30, body.StandInVertexWrites);
            Assert.Equal(30, garment.StandInNormalWrites);
            Assert.Equal(30, garment.StandInRecalculatedBounds);

            // What the Mesh got is the garment, in Unity's space (x negated), with Drape's normals.
            var raw = new Vector3f[dresser.Garment.VertexCount];
            var rawNormals = new Vector3f[dresser.Garment.VertexCount];
            dresser.Garment.ReadMesh(raw, rawNormals, Span<uint>.Empty);
            Vector3[] v = garment.StandInVertices!;
            for (int i = 0; i < raw.Length; ++i)
            {
                Assert.Equal(-raw[i].X, v[i].x);
                Assert.Equal(raw[i].Y, v[i].y);
                Assert.Equal(raw[i].Z, v[i].z);
                Assert.Equal(-rawNormals[i].X, garment.StandInNormals![i].x);
            }

            // The steady state allocates nothing (the recording loops at 30 Hz under a 60 Hz display).
            var method = typeof(DrapeDresser).GetMethod("Update", BindingFlags.Instance | BindingFlags.NonPublic)!;
            var update = (Action)Delegate.CreateDelegate(typeof(Action), dresser, method);
            for (int i = 0; i < 20; ++i) update();
            long before = GC.GetAllocatedBytesForCurrentThread();
            for (int i = 0; i < 100; ++i) update();
            long allocated = GC.GetAllocatedBytesForCurrentThread() - before;
            _output.WriteLine($"DrapeDresser.Update: {allocated} bytes allocated in 100 frames; " +
                              $"{dresser.Loop.FramesAccepted} frames accepted, {dresser.Loop.Steps} steps");
            Assert.Equal(0L, allocated);
            Assert.Equal(0L, dresser.Loop.RejectedFrames);

            // OnDisable frees the native objects and the meshes.
            DressingLoop loop = dresser.Loop;
            Message(dresser, "OnDisable");
            Assert.True(loop.Context.IsDisposed);
            Assert.True(garment.IsDestroyedStandIn);
            Assert.True(body.IsDestroyedStandIn);
            Assert.Null(dresser.Loop);
            Recording rec = source.Source.Recording;
            Message(source, "OnDestroy");
            Assert.True(rec.IsDisposed);
        }

        [Fact]
        public void DrapeDresser_WithoutASource_LogsAndDisablesItself()
        {
            var go = new GameObject("nobody");
            var dresser = go.AddComponent<DrapeDresser>();
            int logged = UnityEngine.Debug.StandInLog.Count;
            Message(dresser, "OnEnable");
            Assert.False(dresser.enabled);
            Assert.Null(dresser.Loop);
            Assert.Contains(UnityEngine.Debug.StandInLog.Skip(logged), m => m.Contains("needs a joint source"));
            Message(dresser, "Update");   // harmless while disabled
        }

        // ---- Sensor sources on the SDK stand-ins -------------------------------------------------

        [Fact]
        public void KinectV2Source_MapsJointTypesInOrder_AndFollowsOneBody()
        {
            var go = new GameObject("kinect");
            var source = go.AddComponent<KinectV2JointSourceBehaviour>();
            Message(source, "OnEnable");
            Assert.Equal(Layout.Kinect2, source.Layout);
            Assert.Equal(25, source.JointCount);
            var joints = new Joint[25];
            Assert.False(source.TryGetFrame(joints, out _));   // no frame yet

            Windows.Kinect.Body Body(ulong id, float dx, bool tracked = true)
            {
                var b = new Windows.Kinect.Body { IsTracked = tracked, TrackingId = id };
                Joint[] pose = SyntheticKinect2.Frame(0);
                for (int j = 0; j < 25; ++j)
                    b.Joints[(Windows.Kinect.JointType)j] = new Windows.Kinect.Joint
                    {
                        JointType = (Windows.Kinect.JointType)j,
                        Position = new Windows.Kinect.CameraSpacePoint { X = pose[j].Position.X + dx, Y = pose[j].Position.Y, Z = pose[j].Position.Z },
                        TrackingState = j == 21 ? Windows.Kinect.TrackingState.Inferred : Windows.Kinect.TrackingState.Tracked,
                    };
                return b;
            }
            Windows.Kinect.KinectSensor.StandInQueue(Body(1, 0f, tracked: false), Body(7, 0.5f), Body(9, 1f));
            Assert.True(source.TryGetFrame(joints, out double t0));
            Joint[] expected = SyntheticKinect2.Frame(0);
            for (int j = 0; j < 25; ++j)
                Assert.Equal(expected[j].Position.X + 0.5f, joints[j].Position.X);   // body 7: the first tracked
            Assert.Equal(TrackingState.Inferred, joints[21].TrackingState);
            Assert.Equal(TrackingState.Tracked, joints[3].TrackingState);

            Windows.Kinect.KinectSensor.StandInQueue(Body(9, 1f), Body(7, 0.6f));   // body 7 is kept
            Assert.True(source.TryGetFrame(joints, out double t1));
            Assert.True(t1 > t0);
            Assert.Equal(expected[0].Position.X + 0.6f, joints[0].Position.X);

            // Through a Context: the frames are valid Kinect2 input.
            using var ctx = new Context();
            ctx.PushSkeleton(joints, source.Layout, t1);
            ctx.Update();
            Message(source, "OnDisable");
            Assert.False(source.TryGetFrame(joints, out _));
        }

        [Fact]
        public void AzureKinectSource_ConvertsMillimetres_Confidence_AndTimestamps()
        {
            var tracker = new Microsoft.Azure.Kinect.BodyTracking.Tracker();
            var source = new AzureKinectJointSource(tracker);
            Assert.Equal(Layout.Azure, source.Layout);
            Assert.Equal(32, source.JointCount);
            var joints = new Joint[32];
            Assert.False(source.TryGetFrame(joints, out _));

            // A Kinect v2 pose re-expressed in Azure's joint order, millimetres, +Y down (180 degrees about X).
            int[] fromV2 = { 0, 1, 20, 2, 20, 4, 5, 6, 7, 21, 22, 20, 8, 9, 10, 11, 23, 24, 12, 13, 14, 15, 16, 17, 18, 19, 3, 3, 3, 3, 3, 3 };
            Joint[] v2 = SyntheticKinect2.Frame(0);
            var k = new Microsoft.Azure.Kinect.BodyTracking.Joint[32];
            for (int j = 0; j < 32; ++j)
            {
                Vector3f p = v2[fromV2[j]].Position;
                k[j].Position = new System.Numerics.Vector3(p.X * 1000f, -p.Y * 1000f, p.Z * 1000f);
                k[j].ConfidenceLevel = (Microsoft.Azure.Kinect.BodyTracking.JointConfidenceLevel)(j % 4);
            }
            tracker.StandInQueue(TimeSpan.FromSeconds(12.5), 3, k);
            Assert.True(source.TryGetFrame(joints, out double t));
            Assert.Equal(12.5, t, 9);
            for (int j = 0; j < 32; ++j)
            {
                Assert.Equal(k[j].Position.X * 0.001f, joints[j].Position.X);
                Assert.Equal(k[j].Position.Y * 0.001f, joints[j].Position.Y);
                Assert.Equal(j % 4 == 0 ? TrackingState.NotTracked : j % 4 == 1 ? TrackingState.Inferred : TrackingState.Tracked,
                             joints[j].TrackingState);
            }
            // The same device time again is not a new frame.
            tracker.StandInQueue(TimeSpan.FromSeconds(12.5), 3, k);
            Assert.False(source.TryGetFrame(joints, out _));

            // Through a Context (the Azure layout, Y down): accepted and meshed.
            for (int j = 0; j < 32; ++j) k[j].ConfidenceLevel = Microsoft.Azure.Kinect.BodyTracking.JointConfidenceLevel.High;
            tracker.StandInQueue(TimeSpan.FromSeconds(12.6), 3, k);
            Assert.True(source.TryGetFrame(joints, out double t2));
            using var ctx = new Context();
            ctx.PushSkeleton(joints, Layout.Azure, t2);
            ctx.Update();
            Assert.True(ctx.GetBodyMeshSize().VertexCount > 0);
        }
    }
}
