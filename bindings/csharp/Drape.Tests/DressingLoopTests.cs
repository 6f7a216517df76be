using System;
using System.Collections.Generic;
using Xunit;
using Xunit.Abstractions;

namespace Drape.Tests
{
    /// <summary>The host-side frame loop of the netstandard2.1 library: IJointSource,
    /// RecordingJointSource, DressingLoop and MeshSpace (what the Unity sample is built from).</summary>
    public class DressingLoopTests
    {
        private readonly ITestOutputHelper _output;

        public DressingLoopTests(ITestOutputHelper output)
        {
            _output = output;
            TestEnvironment.RequireNativeLibrary();
        }

        private static GarmentTemplate SmallShirt(uint particles = 400)
        {
            GarmentTemplate t = GarmentTemplate.CreateDefault(GarmentKind.TShirt);
            t.Particles = particles;
            return t;
        }

        /// <summary>A source handing out a list of frames, one per call (some may be bad).</summary>
        private sealed class ListSource : IJointSource
        {
            private readonly List<(Joint[] Joints, double T)> _frames = new List<(Joint[], double)>();
            private int _next;
            public double Advanced;
            public Layout Layout => Layout.Kinect2;
            public int JointCount => SyntheticKinect2.JointCount;
            public void Add(Joint[] joints, double t) => _frames.Add((joints, t));
            public void Advance(double deltaS) => Advanced += deltaS;
            public bool TryGetFrame(Span<Joint> joints, out double timestampS)
            {
                timestampS = 0;
                if (_next >= _frames.Count) return false;
                var (j, t) = _frames[_next++];
                j.CopyTo(joints);
                timestampS = t;
                return true;
            }
        }

        // ---- RecordingJointSource ----------------------------------------------------------------

        [Fact]
        public void RecordingSource_EveryCall_HandsOutEachFrameOnce_ThenLoopsWithIncreasingTimes()
        {
            using var src = RecordingJointSource.OpenMemory(SyntheticKinect2.Csv(5));
            src.Mode = PlaybackMode.EveryCall;
            Assert.Equal(Layout.Kinect2, src.Layout);
            Assert.Equal(25, src.JointCount);
            Assert.Equal(1.0 / 30.0, src.FramePeriodS, 3);
            var joints = new Joint[25];
            var times = new List<double>();
            for (int i = 0; i < 12; ++i)
            {
                Assert.True(src.TryGetFrame(joints, out double t));
                times.Add(t);
                int frame = i % 5;
                Assert.Equal(SyntheticKinect2.Frame(frame)[0].Position.X, joints[0].Position.X, 5);
            }
            Assert.Equal(0.0, times[0]);
            for (int i = 1; i < times.Count; ++i) Assert.True(times[i] > times[i - 1], $"time {i} does not increase");
            Assert.Equal(2, src.Repetitions);
            // Looping restarts one period after the last frame.
            Assert.Equal(times[4] + src.FramePeriodS, times[5], 6);

            src.Loop = false;
            src.Rewind();
            for (int i = 0; i < 5; ++i) Assert.True(src.TryGetFrame(joints, out _));
            Assert.True(src.IsFinished);
            Assert.False(src.TryGetFrame(joints, out double none));
            Assert.Equal(0.0, none);
        }

        [Fact]
        public void RecordingSource_RealTime_FollowsTheHostClock_AndSkipsFramesWhenBehind()
        {
            using var src = RecordingJointSource.OpenMemory(SyntheticKinect2.Csv(30));
            var joints = new Joint[25];
            Assert.True(src.TryGetFrame(joints, out double t0));        // frame 0 is due at once
            Assert.Equal(0.0, t0);
            Assert.False(src.TryGetFrame(joints, out _));                // nothing new without time passing
            src.Advance(0.010);
            Assert.False(src.TryGetFrame(joints, out _));                // 10 ms: frame 1 (33 ms) not due
            src.Advance(0.030);
            Assert.True(src.TryGetFrame(joints, out double t1));
            Assert.Equal(2, src.NextFrameIndex);
            Assert.Equal(SyntheticKinect2.Time(1), t1, 6);
            src.Advance(0.2);                                            // host stalled: newest due frame wins
            Assert.True(src.TryGetFrame(joints, out double t2));
            Assert.Equal(7, src.NextFrameIndex - 1);
            Assert.Equal(SyntheticKinect2.Time(7), t2, 6);
            Assert.Equal(SyntheticKinect2.Frame(7)[3].Position.X, joints[3].Position.X, 5);

            src.Speed = 2.0;
            src.Advance(1.0);                                            // 2 s of a 1 s recording: wraps
            Assert.True(src.TryGetFrame(joints, out double t3));
            Assert.True(t3 > t2);
            Assert.True(src.Repetitions >= 1);

            Assert.Throws<ArgumentOutOfRangeException>(() => src.Advance(-1));
            Assert.Throws<ArgumentOutOfRangeException>(() => src.Advance(double.NaN));
            Assert.Throws<ArgumentOutOfRangeException>(() => src.Speed = double.PositiveInfinity);
        }

        [Fact]
        public void RecordingSource_OwnsItsRecordingOnlyWhenAsked()
        {
            var rec = Recording.OpenMemory(SyntheticKinect2.Csv(3));
            using (var borrowed = new RecordingJointSource(rec)) { }
            Assert.False(rec.IsDisposed);
            var owner = new RecordingJointSource(rec, ownsRecording: true);
            owner.Dispose();
            Assert.True(rec.IsDisposed);
            Assert.Throws<ObjectDisposedException>(() => owner.TryGetFrame(new Joint[25], out _));
            Assert.Throws<ArgumentNullException>(() => new RecordingJointSource(null!));
        }

        // ---- DressingLoop ------------------------------------------------------------------------

        [Fact]
        public void Loop_HostDelta_StepsEveryTick_AfterTheFirstFrame()
        {
            var src = new ListSource();
            for (int i = 0; i < 3; ++i) src.Add(SyntheticKinect2.Frame(i), SyntheticKinect2.Time(i));
            using var loop = new DressingLoop(src);
            using Garment g = loop.Context.AddGarment(SmallShirt());

            Assert.False(loop.HasBody);
            Assert.True(loop.Tick(1 / 60f));            // frame 0
            Assert.True(loop.HasBody);
            Assert.True(loop.Tick(1 / 60f));            // frame 1
            Assert.True(loop.Tick(1 / 60f));            // frame 2
            Assert.False(loop.Tick(1 / 60f));           // no new frame: the cloth still moves
            Assert.False(loop.Tick(1 / 60f));
            Assert.Equal(5L, loop.Steps);
            Assert.Equal(5UL, g.Stats.Steps);
            Assert.Equal(1 / 60f, loop.LastStepDtS);
            Assert.Equal(3L, loop.FramesAccepted);
            Assert.Equal(5.0 / 60.0, src.Advanced, 6);

            Assert.False(loop.Tick(0f));                // paused game: no cloth step
            Assert.Equal(5UL, g.Stats.Steps);
            Assert.Throws<ArgumentOutOfRangeException>(() => loop.Tick(-1f));
            Assert.Throws<ArgumentOutOfRangeException>(() => loop.Tick(float.NaN));
        }

        [Fact]
        public void Loop_BeforeAnyFrame_StepsNothing()
        {
            var src = new ListSource();
            using var loop = new DressingLoop(src);
            using Garment g = loop.Context.AddGarment(SmallShirt());
            for (int i = 0; i < 3; ++i) Assert.False(loop.Tick(1 / 30f));
            Assert.Equal(0L, loop.Steps);
            Assert.Equal(0UL, g.Stats.Steps);
        }

        [Fact]
        public void Loop_SourceTimestamps_StepsByTimestampDifferences()
        {
            var src = new ListSource();
            double[] times = { 0.0, 0.05, 0.06, 0.2 };
            for (int i = 0; i < times.Length; ++i) src.Add(SyntheticKinect2.Frame(i), times[i]);
            using var loop = new DressingLoop(src) { Timing = StepTiming.SourceTimestamps, FirstFrameDtS = 0.025 };
            using Garment g = loop.Context.AddGarment(SmallShirt());
            var dts = new List<float>();
            for (int i = 0; i < 6; ++i)
                if (loop.Tick(1 / 60f)) dts.Add(loop.LastStepDtS);
            Assert.Equal(new[] { 0.025f, 0.05f, (float)(0.06 - 0.05), (float)(0.2 - 0.06) }, dts);
            Assert.Equal(4UL, g.Stats.Steps);           // no step without a new frame
            Assert.Throws<ArgumentOutOfRangeException>(() => loop.FirstFrameDtS = 0);
        }

        [Fact]
        public void Loop_CountsRejectedFrames_AndGoesOn()
        {
            var src = new ListSource();
            src.Add(SyntheticKinect2.Frame(0), 0.0);
            Joint[] nan = SyntheticKinect2.Frame(1);
            nan[4].Position.Y = float.NaN;
            src.Add(nan, 1 / 30.0);
            src.Add(SyntheticKinect2.Frame(2), 1 / 30.0);     // fine
            src.Add(SyntheticKinect2.Frame(3), 1 / 30.0);     // same timestamp again: rejected
            src.Add(SyntheticKinect2.Frame(4), 4 / 30.0);
            using var loop = new DressingLoop(src) { Timing = StepTiming.SourceTimestamps };
            using Garment g = loop.Context.AddGarment(SmallShirt());
            bool[] accepted = new bool[5];
            for (int i = 0; i < 5; ++i) accepted[i] = loop.Tick(1 / 30f);
            Assert.Equal(new[] { true, false, true, false, true }, accepted);
            Assert.Equal(5L, loop.FramesReceived);
            Assert.Equal(3L, loop.FramesAccepted);
            Assert.Equal(2L, loop.RejectedFrames);
            Assert.Equal(ResultCode.Timestamp, loop.LastRejection!.Code);
            Assert.Equal(3UL, g.Stats.Steps);
            Assert.Equal(2u, loop.Context.GetFrameStats().FramesRejected);
            _output.WriteLine(loop.LastRejection.Message);
        }

        [Fact]
        public void Loop_WithoutGarments_UpdatesTheBodyOnNewFrames()
        {
            var src = new ListSource();
            src.Add(SyntheticKinect2.Frame(0), 0.0);
            src.Add(SyntheticKinect2.Frame(1), 0.1);
            using var loop = new DressingLoop(src);
            Assert.True(loop.Tick(1 / 30f));
            Assert.True(loop.Tick(1 / 30f));
            Assert.False(loop.Tick(1 / 30f));
            Assert.Equal(2L, loop.Steps);
            Assert.Equal(2u, loop.Context.GetFrameStats().Updates);
        }

        [Fact]
        public void Loop_RejectsABadSource_AndDisposesAnOwnedOne()
        {
            Assert.Throws<ArgumentNullException>(() => new DressingLoop(null!));
            var src = RecordingJointSource.OpenMemory(SyntheticKinect2.Csv(3));
            var loop = new DressingLoop(src, ownsSource: true);
            Assert.Equal(src.FramePeriodS, loop.FirstFrameDtS);
            Context ctx = loop.Context;
            loop.Dispose();
            loop.Dispose();
            Assert.True(ctx.IsDisposed);
            Assert.True(src.Recording.IsDisposed);
            Assert.Throws<ObjectDisposedException>(() => loop.Tick(1 / 30f));
        }

        // ---- MeshSpace ---------------------------------------------------------------------------

        [Fact]
        public void MeshSpace_FlipsPositionsNormalsAndWinding_Consistently()
        {
            using var src = RecordingJointSource.OpenMemory(SyntheticKinect2.Csv(10));
            using var loop = new DressingLoop(src);
            using Garment g = loop.Context.AddGarment(SmallShirt());
            for (int i = 0; i < 10; ++i) loop.Tick(1 / 30f);

            var raw = new Vector3f[g.VertexCount];
            var rawNormals = new Vector3f[g.VertexCount];
            var rawIndices = new uint[g.IndexCount];
            g.ReadMesh(raw, rawNormals, rawIndices);
            foreach (AxisFlip flip in new[] { AxisFlip.None, AxisFlip.X, AxisFlip.Z })
            {
                var p = new Vector3f[g.VertexCount + 3];          // longer than needed: the tail is untouched
                p[g.VertexCount] = new Vector3f(7, 8, 9);
                var n = new Vector3f[g.VertexCount];
                var tri = new int[g.IndexCount];
                MeshSpace.ReadGarment(g, p, n, flip);
                MeshSpace.ReadGarmentTriangles(g, tri, flip);
                Assert.Equal(new Vector3f(7, 8, 9), p[g.VertexCount]);
                for (int v = 0; v < g.VertexCount; ++v)
                {
                    Assert.Equal(flip == AxisFlip.X ? -raw[v].X : raw[v].X, p[v].X);
                    Assert.Equal(raw[v].Y, p[v].Y);
                    Assert.Equal(flip == AxisFlip.Z ? -raw[v].Z : raw[v].Z, p[v].Z);
                    Assert.Equal(flip == AxisFlip.X ? -rawNormals[v].X : rawNormals[v].X, n[v].X);
                    Assert.Equal(flip == AxisFlip.Z ? -rawNormals[v].Z : rawNormals[v].Z, n[v].Z);
                }
                // Faces keep agreeing with the vertex normals: the winding turned with the reflection.
                Assert.True(AgreeingFaces(p, n, tri) > 0.9, $"{flip}: face winding disagrees with the normals");
                for (int t = 0; t < tri.Length; t += 3)
                {
                    Assert.Equal((int)rawIndices[t], tri[t]);
                    Assert.Equal((int)rawIndices[t + (flip == AxisFlip.None ? 1 : 2)], tri[t + 1]);
                }
            }

            // The body the same way.
            var (vc, ic) = loop.Context.GetBodyMeshSize();
            var bp = new Vector3f[vc];
            var bn = new Vector3f[vc];
            var bt = new int[ic];
            MeshSpace.ReadBody(loop.Context, bp, bn, AxisFlip.X);
            MeshSpace.ReadBodyTriangles(loop.Context, bt, AxisFlip.X);
            Assert.True(AgreeingFaces(bp, bn, bt) > 0.95);
            MeshSpace.ReadBody(loop.Context, bp, Span<Vector3f>.Empty, AxisFlip.None);   // normals skipped

            Assert.Throws<ArgumentException>(() => MeshSpace.ApplyWinding(new int[4], AxisFlip.X));
            Assert.Throws<ArgumentOutOfRangeException>(() => MeshSpace.Apply(new Vector3f[1], (AxisFlip)7));
            Assert.Throws<DrapeException>(() => MeshSpace.ReadGarment(g, new Vector3f[g.VertexCount - 1], Span<Vector3f>.Empty, AxisFlip.X));
        }

        // Fraction of triangles whose geometric normal (from the winding) points along their vertex normals.
        private static double AgreeingFaces(Vector3f[] p, Vector3f[] n, int[] tri)
        {
            int agree = 0, total = 0;
            for (int t = 0; t < tri.Length; t += 3)
            {
                Vector3f a = p[tri[t]], b = p[tri[t + 1]], c = p[tri[t + 2]];
                float ux = b.X - a.X, uy = b.Y - a.Y, uz = b.Z - a.Z;
                float vx = c.X - a.X, vy = c.Y - a.Y, vz = c.Z - a.Z;
                float fx = uy * vz - uz * vy, fy = uz * vx - ux * vz, fz = ux * vy - uy * vx;
                Vector3f m = n[tri[t]], m1 = n[tri[t + 1]], m2 = n[tri[t + 2]];
                float d = fx * (m.X + m1.X + m2.X) + fy * (m.Y + m1.Y + m2.Y) + fz * (m.Z + m1.Z + m2.Z);
                if (d == 0f) continue;
                total++;
                if (d > 0f) agree++;
            }
            return total == 0 ? 0 : (double)agree / total;
        }

        // ---- Allocation --------------------------------------------------------------------------

        /// <summary>A game's frame: Tick (source advance, push, step) and both meshes read through
        /// MeshSpace, 100 times after a warm-up: 0 managed bytes.</summary>
        [Fact]
        public void SteadyStateTicks_AllocateNothing()
        {
            using var src = RecordingJointSource.OpenMemory(SyntheticKinect2.Csv(60));   // loops
            using var loop = new DressingLoop(src);
            using Garment g = loop.Context.AddGarment(SmallShirt());
            var gp = new Vector3f[g.VertexCount];
            var gn = new Vector3f[g.VertexCount];
            var (vc, _) = loop.Context.GetBodyMeshSize();
            var bp = new Vector3f[vc];
            var bn = new Vector3f[vc];
            const float dt = 1 / 60f;   // display faster than the sensor: ticks with and without frames
            void Frame()
            {
                loop.Tick(dt);
                MeshSpace.ReadGarment(g, gp, gn, AxisFlip.X);
                MeshSpace.ReadBody(loop.Context, bp, bn, AxisFlip.X);
            }
            for (int i = 0; i < 30; ++i) Frame();
            long before = GC.GetAllocatedBytesForCurrentThread();
            for (int i = 0; i < 100; ++i) Frame();
            long allocated = GC.GetAllocatedBytesForCurrentThread() - before;
            _output.WriteLine($"{allocated} bytes allocated in 100 ticks ({loop.FramesAccepted} frames accepted)");
            Assert.Equal(0L, allocated);
            Assert.Equal(130L, loop.Steps);
            Assert.True(loop.FramesAccepted >= 60, $"only {loop.FramesAccepted} frames accepted");   // the recording looped
            Assert.Equal(0L, loop.RejectedFrames);
        }
    }
}
