using System;
using System.Collections.Generic;
using System.Globalization;
using System.IO;
using Xunit;
using Xunit.Abstractions;

namespace Drape.Tests
{
    /// <summary>
    /// A real recording from the shared data replayed through C# (RecordingJointSource in EveryCall
    /// mode + DressingLoop with SourceTimestamps, i.e. drape-replay's dt rule: the first frame one
    /// nominal period, then timestamp differences) gives the vertices the native drape-replay writes
    /// (its body_NNNNN.obj and garment_NNNNN.obj, "%.6f" metres, "%.5f" normals). Both run the same
    /// library build, so the only difference allowed is the OBJ's rounding: half a unit of its last
    /// digit (5e-7 m for positions), plus a float's rounding when printed.
    /// </summary>
    public class ReplayParityTests
    {
        private const int Frames = 20;
        private readonly ITestOutputHelper _output;

        public ReplayParityTests(ITestOutputHelper output)
        {
            _output = output;
            TestEnvironment.RequireNativeLibrary();
        }

        public static IEnumerable<object[]> Recordings() => new[]
        {
            new object[] { "kinect_v2_msft_labanotation/Ges02_balancinghands.csv" },
            new object[] { "cmu_mocap_bvh/131_03.bvh" },
        };

        [Theory]
        [MemberData(nameof(Recordings))]
        public void CSharpReplay_MatchesNativeDrapeReplay(string relative)
        {
            string? recording = TestEnvironment.SharedFile(relative, out string why);
            if (recording == null)
            {
                _output.WriteLine($"SKIPPED: {why}. Set DRAPE_SHARED_DATA to the shared/data folder to run this test.");
                return;
            }
            string replay = TestEnvironment.Metadata("DrapeReplay");
            Assert.True(File.Exists(replay),
                $"the native drape-replay is not at '{replay}' (the DrapeReplay property; default: DrapeNativeDir/../samples/drape-replay). " +
                "Build it: cmake --build --preset release --target drape-replay");

            using var dir = new TestProcess.TempDir("drape-parity");
            var args = new List<string>
            {
                "--recording", recording, "--frames", Frames.ToString(CultureInfo.InvariantCulture),
                "--out", dir.Path, "--stats", Path.Combine(dir.Path, "stats.json"), "--quiet",
            };
            // Builds that draw pictures (docs/replay.md, "Pictures") are told not to: only the OBJs count here.
            if (TestProcess.Run(replay, new[] { "--help" }).Output.Contains("--no-render")) args.Add("--no-render");
            TestProcess.Result r = TestProcess.Run(replay, args);
            Assert.True(r.ExitCode == 0, $"drape-replay failed: {r}");

            // C#: what drape-replay does, through the host-side loop.
            using var source = RecordingJointSource.Open(recording);
            source.Mode = PlaybackMode.EveryCall;
            source.Loop = false;
            using var loop = new DressingLoop(source) { Timing = StepTiming.SourceTimestamps };
            Assert.Equal(1.0 / source.Recording.Info.NominalRateHz, loop.FirstFrameDtS, 12);
            ClothParams cloth = ClothParams.CreateDefault();
            uint perFrame = (uint)Math.Ceiling(cloth.SubstepHz / 30.0f);            // drape-replay's substep cap rule
            cloth.MaxSubsteps = Math.Max(cloth.MaxSubsteps, Math.Min(1000u, 2 * perFrame));
            Garment shirt = loop.Context.AddGarment(GarmentTemplate.CreateDefault(GarmentKind.TShirt), null, cloth);

            var (bodyVertices, bodyIndexCount) = loop.Context.GetBodyMeshSize();
            var bodyPositions = new Vector3f[bodyVertices];
            var bodyNormals = new Vector3f[bodyVertices];
            var bodyIndices = new uint[bodyIndexCount];
            loop.Context.ReadBodyMesh(Span<Vector3f>.Empty, Span<Vector3f>.Empty, bodyIndices);
            var positions = new Vector3f[shirt.VertexCount];
            var normals = new Vector3f[shirt.VertexCount];
            var indices = new uint[shirt.IndexCount];
            shirt.ReadIndices(indices);

            int frames = Math.Min(Frames, (int)source.Recording.Info.FrameCount);
            double worstPosition = 0, worstNormal = 0;
            int compared = 0;
            for (int i = 0; i < frames; ++i)
            {
                bool accepted = loop.Tick((float)source.FramePeriodS);
                string bodyObj = Path.Combine(dir.Path, $"body_{i:D5}.obj");
                string garmentObj = Path.Combine(dir.Path, $"garment_{i:D5}.obj");
                Assert.Equal(File.Exists(bodyObj), accepted);   // drape-replay writes only accepted frames
                if (!accepted) continue;

                loop.Context.ReadBodyMesh(bodyPositions, bodyNormals, Span<uint>.Empty);
                Compare(bodyObj, bodyPositions, bodyNormals, bodyIndices, ref worstPosition, ref worstNormal);
                shirt.ReadMesh(positions, normals, Span<uint>.Empty);
                Compare(garmentObj, positions, normals, indices, ref worstPosition, ref worstNormal);
                compared++;
            }
            _output.WriteLine($"{relative}: {compared} frames of body ({bodyVertices} vertices) and T-shirt " +
                              $"({shirt.VertexCount} particles, {shirt.Stats.Steps} steps) compared; " +
                              $"largest difference {worstPosition:E2} m (positions), {worstNormal:E2} (normals)");
            Assert.True(compared >= frames - 2, $"only {compared} of {frames} frames were accepted");
            Assert.Equal((ulong)compared, shirt.Stats.Steps);
        }

        // The OBJ against C#'s arrays: positions within the "%.6f" rounding (5e-7) plus the float's own
        // rounding at that magnitude, normals within "%.5f"'s (5e-6); same faces.
        private static void Compare(string objPath, Vector3f[] positions, Vector3f[] normals, uint[] indices,
                                    ref double worstPosition, ref double worstNormal)
        {
            var (v, vn, f) = ReadObj(objPath);
            Assert.Equal(positions.Length, v.Count);
            Assert.Equal(normals.Length, vn.Count);
            Assert.Equal(indices.Length, f.Count);
            for (int i = 0; i < v.Count; ++i)
            {
                for (int c = 0; c < 3; ++c)
                {
                    double mine = c == 0 ? positions[i].X : c == 1 ? positions[i].Y : positions[i].Z;
                    double d = Math.Abs(mine - v[i][c]);
                    worstPosition = Math.Max(worstPosition, d);
                    Assert.True(d <= 5e-7 + 1e-9, $"{Path.GetFileName(objPath)}: vertex {i}[{c}] = {mine:R} in C#, {v[i][c]:F6} in drape-replay");
                    double mineN = c == 0 ? normals[i].X : c == 1 ? normals[i].Y : normals[i].Z;
                    double dn = Math.Abs(mineN - vn[i][c]);
                    worstNormal = Math.Max(worstNormal, dn);
                    Assert.True(dn <= 5e-6 + 1e-9, $"{Path.GetFileName(objPath)}: normal {i}[{c}] = {mineN:R} in C#, {vn[i][c]:F5} in drape-replay");
                }
            }
            for (int i = 0; i < f.Count; ++i)
                Assert.True(indices[i] == f[i], $"{Path.GetFileName(objPath)}: index {i} is {indices[i]} in C#, {f[i]} in drape-replay");
        }

        private static (List<double[]> V, List<double[]> Vn, List<uint> F) ReadObj(string path)
        {
            var v = new List<double[]>();
            var vn = new List<double[]>();
            var f = new List<uint>();
            foreach (string line in File.ReadLines(path))
            {
                string[] s = line.Split(' ', StringSplitOptions.RemoveEmptyEntries);
                if (s.Length == 0) continue;
                switch (s[0])
                {
                    case "v":
                        v.Add(new[] { Num(s[1]), Num(s[2]), Num(s[3]) });
                        break;
                    case "vn":
                        vn.Add(new[] { Num(s[1]), Num(s[2]), Num(s[3]) });
                        break;
                    case "f":
                        for (int k = 1; k <= 3; ++k)
                            f.Add(uint.Parse(s[k].Split('/')[0], CultureInfo.InvariantCulture) - 1);   // 1-based
                        break;
                }
            }
            return (v, vn, f);
        }

        private static double Num(string s) => double.Parse(s, NumberStyles.Float, CultureInfo.InvariantCulture);
    }
}
