using System;
using System.Diagnostics;
using System.Globalization;
using System.Linq;
using System.IO;
using System.Runtime.InteropServices;
using Xunit;
using Xunit.Abstractions;

namespace Drape.Tests
{
    /// <summary>Tests that measure the whole process (native heap, RSS) run alone, after the others.</summary>
    [CollectionDefinition(Name, DisableParallelization = true)]
    public sealed class SerialCollection
    {
        public const string Name = "Serial (process-wide measurements)";
    }

    /// <summary>
    /// Create/destroy cycles of every native object the bindings own leave no native memory behind:
    /// glibc's heap in use (mallinfo2: uordblks + hblkhd, every arena) and the resident set size are
    /// sampled (with the garbage collector held off) once a warm-up has filled the allocator's caches
    /// and let the runtime tier its code up (see Measure); no object may be reported leaked
    /// (DrapeLibrary.LeakedHandleCount). 10 000 cycles of contexts (with a frame pushed and updated),
    /// recordings and failed creations: a leak of 100 bytes per cycle fails. Garments cost one to
    /// seven milliseconds each to create (proxies, collision groups, constraints), so 2 000 small
    /// mesh garments (500 B per cycle fails) and 200 template T-shirts (2 000 B per cycle fails;
    /// a 200-particle T-shirt holds tens of kB).
    /// </summary>
    [Collection(SerialCollection.Name)]
    public class LifecycleStressTests
    {
        private const int Cycles = 10_000;
        private readonly ITestOutputHelper _output;

        public LifecycleStressTests(ITestOutputHelper output)
        {
            _output = output;
            TestEnvironment.RequireNativeLibrary();
        }

        [StructLayout(LayoutKind.Sequential)]
        private struct MallInfo2
        {
            public UIntPtr Arena, Ordblks, Smblks, Hblks, Hblkhd, Usmblks, Fsmblks, Uordblks, Fordblks, Keepcost;
        }

        [DllImport("libc", EntryPoint = "mallinfo2")]
        private static extern MallInfo2 mallinfo2();

        /// <summary>Bytes the C heap has handed out and not got back, or -1 where mallinfo2 is missing.</summary>
        private static long NativeHeapInUse()
        {
            if (!OperatingSystem.IsLinux()) return -1;
            try
            {
                MallInfo2 m = mallinfo2();
                return (long)(ulong)m.Uordblks + (long)(ulong)m.Hblkhd;
            }
            catch (EntryPointNotFoundException) { return -1; }   // glibc < 2.33, musl
            catch (DllNotFoundException) { return -1; }
        }

        private static long Rss()
        {
            using var p = Process.GetCurrentProcess();
            p.Refresh();
            return p.WorkingSet64;
        }

        private static void Settle()
        {
            for (int i = 0; i < 3; ++i)
            {
                GC.Collect();
                GC.WaitForPendingFinalizers();
            }
        }

        private const int Chunks = 20;

        /// <summary>Runs <paramref name="cycle"/> <paramref name="cycles"/> times in 20 chunks, sampling
        /// the C heap after each. A leak adds about the same to every chunk; the runtime's own native
        /// allocations (a few MB at once, now and then: JIT tiering, the test host's threads) add to
        /// one or two. So the check is on the median chunk: under <paramref name="maxBytesPerCycle"/>
        /// per cycle; the whole run must also stay under 16 MB, and RSS under 48 MB.</summary>
        private void Measure(string what, Action cycle, int cycles = Cycles, int warmup = 300, int maxBytesPerCycle = 100,
                             long noGcBudget = 64L << 20)
        {
            // Warm-up: allocator caches, and the runtime tiering the loop's code up.
            var warm = Stopwatch.StartNew();
            for (int i = 0; i < warmup || warm.Elapsed.TotalSeconds < 1.0; ++i) cycle();
            warm.Stop();
            Settle();
            long leakedBefore = DrapeLibrary.LeakedHandleCount;
            long rss0 = Rss();
            // No garbage collection while measuring: the GC's bookkeeping lives in the C heap too.
            bool noGc;
            try { noGc = GC.TryStartNoGCRegion(noGcBudget); }
            catch (NotImplementedException) { noGc = false; }   // Mono
            int perChunk = cycles / Chunks;
            var samples = new long[Chunks + 1];
            samples[0] = NativeHeapInUse();
            var clock = Stopwatch.StartNew();
            for (int k = 1; k <= Chunks; ++k)
            {
                for (int i = 0; i < perChunk; ++i) cycle();
                samples[k] = NativeHeapInUse();
            }
            clock.Stop();
            if (noGc)
            {
                try { GC.EndNoGCRegion(); }
                catch (InvalidOperationException) { noGc = false; }   // the budget ran out: a GC happened
            }
            Settle();
            long rss1 = Rss();
            long[] steps = new long[Chunks];
            for (int k = 0; k < Chunks; ++k) steps[k] = samples[k + 1] - samples[k];
            long[] sorted = (long[])steps.Clone();
            Array.Sort(sorted);
            long median = sorted[Chunks / 2];
            long total = samples[Chunks] - samples[0];
            _output.WriteLine($"{what}: {perChunk * Chunks} cycles in {clock.Elapsed.TotalSeconds:0.00} s (after " +
                              $"{warm.Elapsed.TotalSeconds:0.0} s of warm-up{(noGc ? "" : "; GC not held off")}); native heap " +
                              $"{samples[0] / 1024} -> {samples[Chunks] / 1024} KiB, median per chunk of {perChunk}: {median} B " +
                              $"(chunks: {string.Join(" ", steps.Select(d => (d / 1024).ToString(CultureInfo.InvariantCulture)))} KiB); " +
                              $"RSS {rss0 / (1 << 20)} -> {rss1 / (1 << 20)} MiB");
            Assert.Equal(leakedBefore, DrapeLibrary.LeakedHandleCount);
            if (samples[0] >= 0)
            {
                Assert.True(median < (long)maxBytesPerCycle * perChunk,
                    $"{what}: the native heap grows by {median} bytes per {perChunk} cycles (median chunk; ~{median / perChunk} B per cycle)");
                Assert.True(total < 16L << 20, $"{what}: the native heap grew by {total >> 20} MiB over {cycles} cycles");
            }
            Assert.True(rss1 - rss0 < 48L << 20, $"{what}: RSS grew by {(rss1 - rss0) >> 20} MiB over {cycles} cycles");
        }

        [Fact]
        public void Contexts_10000CreateUseDestroyCycles_LeakNothing()
        {
            Joint[] pose = SyntheticKinect2.Frame(0);
            var indices = new uint[1];
            Measure("Context (create, push, update, destroy)", () =>
            {
                using var ctx = new Context();
                ctx.PushSkeleton(pose, Layout.Kinect2, 0.0);
                ctx.Update();
                _ = ctx.GetFrameStats();
            });
        }

        [Fact]
        public void Recordings_10000OpenReadDestroyCycles_LeakNothing()
        {
            byte[] csv = SyntheticKinect2.Csv(3);
            var joints = new Joint[25];
            Measure("Recording (open from memory, read, destroy)", () =>
            {
                using var rec = Recording.OpenMemory(csv);
                rec.ReadFrame(2, joints, out _);
            });
        }

        [Fact]
        public void Garments_AddDestroyCycles_LeakNothing()
        {
            using var ctx = new Context();
            ctx.PushSkeleton(SyntheticKinect2.Frame(0), Layout.Kinect2, 0.0);
            ctx.Update();
            GarmentDesc d = GarmentDesc.CreateDefault();
            d.DressTimeS = 0f;

            // A 4 x 4 grid of vertices: a free cloth.
            var grid = new Vector3f[16];
            for (int i = 0; i < 16; ++i) grid[i] = new Vector3f(i % 4 * 0.1f, i / 4 * 0.1f, 0f);
            var quads = new System.Collections.Generic.List<uint>();
            for (uint y = 0; y < 3; ++y)
                for (uint x = 0; x < 3; ++x)
                {
                    uint a = y * 4 + x;
                    quads.AddRange(new[] { a, a + 1, a + 4, a + 1, a + 5, a + 4 });
                }
            uint[] tris = quads.ToArray();
            var positions = new Vector3f[16];
            Measure("Garment (add a 16-vertex mesh, read, destroy)", () =>
            {
                using Garment g = ctx.AddGarmentMesh(grid, tris, null, d);
                g.ReadPositions(positions);
            }, cycles: 2_000, warmup: 100, maxBytesPerCycle: 500);

            GarmentTemplate t = GarmentTemplate.CreateDefault(GarmentKind.TShirt);
            t.Particles = 200;
            Measure("Garment (add a 200-particle T-shirt, destroy)", () =>
            {
                using Garment g = ctx.AddGarment(t, d);
            }, cycles: 200, warmup: 20, maxBytesPerCycle: 2_000);
        }

        [Fact]
        public void FailedCreations_LeakNothing()
        {
            // Error paths allocate and free too: an invalid desc, a malformed recording.
            ContextDesc bad = ContextDesc.CreateDefault();
            bad.RingPoints = 3;
            byte[] garbage = System.Text.Encoding.ASCII.GetBytes("not,a,recording\n");
            // The runtime's own native caches grow with the first ~10 000 exceptions a process
            // throws (measured with a managed-only throw: ~130 B each, then flat): warm up past that.
            Measure("failed Context and Recording creations", () =>
            {
                Assert.Throws<DrapeException>(() => new Context(bad));
                Assert.Throws<DrapeException>(() => Recording.OpenMemory(garbage));
            }, warmup: 12_000, noGcBudget: 200L << 20);
        }
    }
}
