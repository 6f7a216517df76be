// Drape C# console sample: replays a skeleton recording through the C# bindings, dresses the person
// in a garment (a 2 000-particle T-shirt by default) and prints per-stage timings: skeleton filter,
// body mesh, collision proxies (drape_frame_stats) and the cloth step with its integrate and collide
// parts (drape_garment_stats), plus the whole managed frame.
//
// It drives the library the way a game would: a DressingLoop takes frames from an IJointSource (here a
// RecordingJointSource) and steps the context. With the default options it runs what the native
// drape-replay runs (one recording frame per tick, dt from the timestamps), so the numbers are
// comparable with drape-replay's stats.
//
//   dotnet run --project samples/csharp -c Release -- --frames 100 --every 10
using System;
using System.Diagnostics;
using System.Globalization;
using System.IO;

namespace Drape.Sample
{
    public static class Program
    {
        public static int Main(string[] args) => Run(args, Console.Out, Console.Error);

        private const string Usage =
            "usage: Drape.Sample [--recording PATH] [--frames N] [--garment KIND] [--particles N] [--every N] [--quiet]\n" +
            "  --recording PATH  Kinect v2 CSV, BVH or .drec (default: data/Ges01_wavehand.csv beside the program)\n" +
            "  --frames N        replay at most N frames (default: all)\n" +
            "  --garment KIND    tshirt|longsleeve|skirt|dress|trousers|none (default tshirt)\n" +
            "  --particles N     the garment's particle count (default: the template's, 2 000)\n" +
            "  --every N         print one line of timings every N frames (default 30; 0: none)\n" +
            "  --quiet           print the summary only\n";

        private sealed class Options
        {
            public string? Recording;
            public int Frames;
            public GarmentKind? Garment = GarmentKind.TShirt;
            public uint Particles;
            public int Every = 30;
        }

        /// <summary>The program, with its output streams as parameters (tests call it).</summary>
        public static int Run(string[] args, TextWriter output, TextWriter error)
        {
            Options opt;
            try
            {
                opt = Parse(args, output, out bool help);
                if (help) return 0;
            }
            catch (ArgumentException e)
            {
                error.WriteLine($"Drape.Sample: {e.Message}");
                error.Write(Usage);
                return 2;
            }
            try
            {
                return Replay(opt, output);
            }
            catch (Exception e) when (e is DrapeException || e is IOException || e is DllNotFoundException ||
                                      e is DrapeVersionMismatchException)
            {
                error.WriteLine($"Drape.Sample: error: {e.Message}");
                return 1;
            }
        }

        private static Options Parse(string[] args, TextWriter output, out bool help)
        {
            var o = new Options();
            help = false;
            for (int i = 0; i < args.Length; ++i)
            {
                string a = args[i];
                string Value() => i + 1 < args.Length ? args[++i] : throw new ArgumentException($"{a} needs a value");
                int Count(string v, int min) =>
                    int.TryParse(v, NumberStyles.None, CultureInfo.InvariantCulture, out int n) && n >= min
                        ? n : throw new ArgumentException($"{a} '{v}' is not a whole number >= {min}");
                switch (a)
                {
                    case "--help": case "-h": output.Write(Usage); help = true; return o;
                    case "--recording": o.Recording = Value(); break;
                    case "--frames": o.Frames = Count(Value(), 1); break;
                    case "--every": o.Every = Count(Value(), 0); break;
                    case "--quiet": case "-q": o.Every = 0; break;
                    case "--particles": o.Particles = (uint)Count(Value(), 1); break;
                    case "--garment":
                        string g = Value();
                        o.Garment = g switch
                        {
                            "tshirt" => GarmentKind.TShirt,
                            "longsleeve" => GarmentKind.LongSleeve,
                            "skirt" => GarmentKind.Skirt,
                            "dress" => GarmentKind.Dress,
                            "trousers" => GarmentKind.Trousers,
                            "none" => (GarmentKind?)null,
                            _ => throw new ArgumentException($"--garment '{g}' is not tshirt, longsleeve, skirt, dress, trousers or none"),
                        };
                        break;
                    default: throw new ArgumentException($"unknown option '{a}'");
                }
            }
            if (o.Garment == null && o.Particles != 0) throw new ArgumentException("--particles has no effect with --garment none");
            return o;
        }

        private static int Replay(Options opt, TextWriter output)
        {
            string path = opt.Recording ?? Path.Combine(AppContext.BaseDirectory, "data", "Ges01_wavehand.csv");
            if (!File.Exists(path)) throw new IOException($"the recording '{path}' does not exist; pass --recording PATH");

            using var source = RecordingJointSource.Open(path);
            source.Mode = PlaybackMode.EveryCall;   // one recording frame per tick
            source.Loop = false;
            RecordingInfo info = source.Recording.Info;
            using var loop = new DressingLoop(source) { Timing = StepTiming.SourceTimestamps };

            Garment? garment = null;
            if (opt.Garment is GarmentKind kind)
            {
                GarmentTemplate tmpl = GarmentTemplate.CreateDefault(kind);
                if (opt.Particles != 0) tmpl.Particles = opt.Particles;
                ClothParams cloth = ClothParams.CreateDefault();
                // As drape-replay: a frame a little longer than 1/30 s must not hit the substep cap.
                uint perFrame = (uint)Math.Ceiling(cloth.SubstepHz / 30f);
                cloth.MaxSubsteps = Math.Max(cloth.MaxSubsteps, Math.Min(1000u, 2 * perFrame));
                garment = loop.Context.AddGarment(tmpl, null, cloth);
            }

            int frames = opt.Frames == 0 ? (int)info.FrameCount : Math.Min(opt.Frames, (int)info.FrameCount);
            output.WriteLine($"Drape {DrapeLibrary.VersionString}: {Path.GetFileName(path)}, {info.Format} {info.Layout}, " +
                             $"{info.FrameCount} frames at {info.NominalRateHz:0.#} Hz; replaying {frames}" +
                             (garment != null ? $", {opt.Garment} with {garment.VertexCount} particles" : ", no garment"));

            // Per-frame samples, allocated once.
            var frameMs = new double[frames];
            var skeletonMs = new double[frames];
            var bodyMs = new double[frames];
            var proxiesMs = new double[frames];
            var clothMs = new double[frames];
            var integrateMs = new double[frames];
            var collideMs = new double[frames];
            int n = 0;
            if (opt.Every > 0)
                output.WriteLine("frame        t    frame  skeleton     body  proxies    cloth integrate  collide  contacts   (ms)");

            var clock = new Stopwatch();
            for (int i = 0; i < frames; ++i)
            {
                clock.Restart();
                bool accepted = loop.Tick((float)source.FramePeriodS);
                clock.Stop();
                if (!accepted) continue;   // a rejected frame: counted by the loop
                FrameStats fs = loop.Context.GetFrameStats();
                frameMs[n] = clock.Elapsed.TotalMilliseconds;
                skeletonMs[n] = fs.SkeletonMs;
                bodyMs[n] = fs.BodyMs;
                proxiesMs[n] = fs.ProxiesMs;
                GarmentStats gs = garment != null ? garment.Stats : default;
                clothMs[n] = gs.StepMs;
                integrateMs[n] = gs.IntegrateMs;
                collideMs[n] = gs.CollideMs;
                if (opt.Every > 0 && (i % opt.Every == 0 || i == frames - 1))
                    output.WriteLine(string.Format(CultureInfo.InvariantCulture,
                        "{0,5} {1,8:0.000} {2,8:0.000} {3,9:0.000} {4,8:0.000} {5,8:0.000} {6,8:0.000} {7,9:0.000} {8,8:0.000} {9,9}",
                        i, fs.LastTimestampS, frameMs[n], skeletonMs[n], bodyMs[n], proxiesMs[n], clothMs[n], integrateMs[n],
                        collideMs[n], gs.Contacts));
                ++n;
            }

            output.WriteLine();
            output.WriteLine($"{loop.FramesAccepted} frames accepted, {loop.RejectedFrames} rejected" +
                             (loop.LastRejection != null ? $" (last: {loop.LastRejection.Message})" : "") +
                             $", {loop.Context.GetFrameStats().Teleports} teleports" +
                             (garment != null ? $", {garment.Stats.Steps} cloth steps" : ""));
            output.WriteLine("stage              mean      p50      p95      max   (ms per frame)");
            Summary(output, "skeleton", skeletonMs, n);
            Summary(output, "body", bodyMs, n);
            Summary(output, "proxies", proxiesMs, n);
            if (garment != null)
            {
                Summary(output, "cloth step", clothMs, n);
                Summary(output, "  integrate", integrateMs, n);
                Summary(output, "  collide", collideMs, n);
            }
            Summary(output, "frame (C#)", frameMs, n);
            return 0;
        }

        private static void Summary(TextWriter output, string name, double[] samples, int count)
        {
            if (count == 0)
            {
                output.WriteLine($"{name,-14}       no frames");
                return;
            }
            var sorted = new double[count];
            Array.Copy(samples, sorted, count);
            Array.Sort(sorted);
            double sum = 0;
            foreach (double v in sorted) sum += v;
            double Percentile(double p) => sorted[Math.Min(count - 1, (int)Math.Ceiling(p * count) - 1)];
            output.WriteLine(string.Format(CultureInfo.InvariantCulture, "{0,-14} {1,8:0.000} {2,8:0.000} {3,8:0.000} {4,8:0.000}",
                                           name, sum / count, Percentile(0.5), Percentile(0.95), sorted[count - 1]));
        }
    }
}
