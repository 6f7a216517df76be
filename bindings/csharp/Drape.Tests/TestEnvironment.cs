using System;
using System.Globalization;
using System.IO;
using System.Linq;
using System.Reflection;
using System.Runtime.InteropServices;
using System.Text;
using Xunit;

namespace Drape.Tests
{
    /// <summary>Where the tests find the native library, the repository and the shared data.</summary>
    internal static class TestEnvironment
    {
        public static string Metadata(string key) =>
            typeof(TestEnvironment).Assembly.GetCustomAttributes<AssemblyMetadataAttribute>()
                .FirstOrDefault(a => a.Key == key)?.Value ?? "";

        /// <summary>The repository root (baked in at build time by Drape.Tests.csproj).</summary>
        public static string RepoRoot => Metadata("DrapeRepoRoot");

        /// <summary>The DrapeNativeDir the test assembly was built with.</summary>
        public static string NativeDir => Metadata("DrapeNativeDir");

        public static string NativeFileName =>
            OperatingSystem.IsWindows() ? "drape.dll" : OperatingSystem.IsMacOS() ? "libdrape.dylib" : "libdrape.so";

        /// <summary>The copy of the native library next to the test assembly.</summary>
        public static string NativePath => Path.Combine(AppContext.BaseDirectory, NativeFileName);

        private static readonly Lazy<string?> s_nativeProblem = new Lazy<string?>(FindNativeProblem);

        /// <summary>Fails the calling test with an explanation (not a bare DllNotFoundException)
        /// when the native library was not copied next to the tests or does not load.</summary>
        public static void RequireNativeLibrary()
        {
            string? problem = s_nativeProblem.Value;
            if (problem != null) Assert.Fail(problem);
        }

        private static string? FindNativeProblem()
        {
            string hint =
                "Build it first, e.g. `cmake --preset release && cmake --build --preset release --target drape` " +
                "(the default DrapeNativeDir is build/release/native), or point the tests at a build: " +
                "`dotnet test bindings/csharp/Drape.Tests -p:DrapeNativeDir=$PWD/build/<dir>/native`.";
            if (!File.Exists(NativePath))
                return $"The native library {NativeFileName} is not next to the tests ({AppContext.BaseDirectory}): " +
                       $"it is copied from DrapeNativeDir = '{NativeDir}', which has none. {hint}";
            try
            {
                NativeLibrary.Free(NativeLibrary.Load(NativePath));
            }
            catch (Exception e)
            {
                return $"The native library {NativePath} exists but does not load: {e.Message}. {hint}";
            }
            return null;
        }

        /// <summary>Where the shared data folder should be: $DRAPE_SHARED_DATA, else ../shared/data
        /// beside the checkout (as the native tests look for it).</summary>
        public static string SharedDataLocation
        {
            get
            {
                string? env = Environment.GetEnvironmentVariable("DRAPE_SHARED_DATA");
                return !string.IsNullOrEmpty(env)
                    ? Path.GetFullPath(env)
                    : Path.GetFullPath(Path.Combine(RepoRoot, "..", "shared", "data"));
            }
        }

        /// <summary>A file under the shared data folder, or null (and why in <paramref name="why"/>).</summary>
        public static string? SharedFile(string relative, out string why)
        {
            string dir = SharedDataLocation;
            string from = string.IsNullOrEmpty(Environment.GetEnvironmentVariable("DRAPE_SHARED_DATA"))
                ? "../shared/data beside the checkout" : "$DRAPE_SHARED_DATA";
            if (!Directory.Exists(dir))
            {
                why = $"the shared data folder {dir} (from {from}) does not exist";
                return null;
            }
            string path = Path.Combine(dir, relative);
            if (!File.Exists(path))
            {
                why = $"{path} does not exist";
                return null;
            }
            why = "";
            return path;
        }

        public static string HeaderText => File.ReadAllText(Path.Combine(RepoRoot, "native", "include", "drape", "drape.h"));
    }

    /// <summary>A synthetic person standing 2.5 m in front of a Kinect v2, swaying a little.
    /// Lets the tests run the whole pipeline without the shared recordings.</summary>
    internal static class SyntheticKinect2
    {
        public const int JointCount = 25;

        // Kinect SDK 2.0 JointType order; metres, y up, z away from the sensor.
        private static readonly float[,] s_pose =
        {
            { 0.00f, 0.00f, 2.50f },   //  0 SpineBase
            { 0.00f, 0.30f, 2.50f },   //  1 SpineMid
            { 0.00f, 0.60f, 2.50f },   //  2 Neck
            { 0.00f, 0.75f, 2.48f },   //  3 Head
            { -0.18f, 0.52f, 2.50f },  //  4 ShoulderLeft
            { -0.24f, 0.25f, 2.50f },  //  5 ElbowLeft
            { -0.27f, 0.02f, 2.48f },  //  6 WristLeft
            { -0.28f, -0.05f, 2.48f }, //  7 HandLeft
            { 0.18f, 0.52f, 2.50f },   //  8 ShoulderRight
            { 0.24f, 0.25f, 2.50f },   //  9 ElbowRight
            { 0.27f, 0.02f, 2.48f },   // 10 WristRight
            { 0.28f, -0.05f, 2.48f },  // 11 HandRight
            { -0.09f, -0.02f, 2.50f }, // 12 HipLeft
            { -0.10f, -0.45f, 2.50f }, // 13 KneeLeft
            { -0.10f, -0.85f, 2.52f }, // 14 AnkleLeft
            { -0.10f, -0.90f, 2.42f }, // 15 FootLeft
            { 0.09f, -0.02f, 2.50f },  // 16 HipRight
            { 0.10f, -0.45f, 2.50f },  // 17 KneeRight
            { 0.10f, -0.85f, 2.52f },  // 18 AnkleRight
            { 0.10f, -0.90f, 2.42f },  // 19 FootRight
            { 0.00f, 0.52f, 2.50f },   // 20 SpineShoulder
            { -0.29f, -0.12f, 2.48f }, // 21 HandTipLeft
            { -0.26f, -0.07f, 2.45f }, // 22 ThumbLeft
            { 0.29f, -0.12f, 2.48f },  // 23 HandTipRight
            { 0.26f, -0.07f, 2.45f },  // 24 ThumbRight
        };

        /// <summary>Frame <paramref name="i"/> of a 30 Hz sequence.</summary>
        public static Joint[] Frame(int i)
        {
            var joints = new Joint[JointCount];
            float sway = 0.02f * MathF.Sin(0.2f * i);
            for (int j = 0; j < JointCount; ++j)
                joints[j] = new Joint(new Vector3f(s_pose[j, 0] + sway, s_pose[j, 1], s_pose[j, 2]), TrackingState.Tracked);
            return joints;
        }

        public static double Time(int i) => i / 30.0;

        /// <summary>The same sequence as a Kinect CSV recording (ticks of 100 ns, no header).</summary>
        public static byte[] Csv(int frames)
        {
            var sb = new StringBuilder();
            const long t0 = 89_810_293_609L;
            for (int i = 0; i < frames; ++i)
            {
                sb.Append((t0 + (long)Math.Round(Time(i) * 1e7)).ToString(CultureInfo.InvariantCulture));
                foreach (Joint j in Frame(i))
                {
                    sb.Append(',').Append(j.Position.X.ToString("R", CultureInfo.InvariantCulture))
                      .Append(',').Append(j.Position.Y.ToString("R", CultureInfo.InvariantCulture))
                      .Append(',').Append(j.Position.Z.ToString("R", CultureInfo.InvariantCulture))
                      .Append(',').Append((int)j.TrackingState);
                }
                sb.Append('\n');
            }
            return Encoding.ASCII.GetBytes(sb.ToString());
        }
    }
}
