using System;
using Xunit;

namespace Drape.Tests
{
    /// <summary>The Adaptive pipeline section through C#: defaults, options round trip, a rejected
    /// value changing nothing, skip statistics, a garment sleeping on a still pose and what wakes it
    /// (docs/adaptive.md).</summary>
    public class PipelineTests
    {
        public PipelineTests() => TestEnvironment.RequireNativeLibrary();

        private static void StillFrames(Context ctx, ref int frame, int count, float dx = 0.0f)
        {
            for (int i = 0; i < count; ++i, ++frame)
            {
                Joint[] j = SyntheticKinect2.Frame(0);
                for (int k = 0; k < j.Length; ++k)
                    j[k] = new Joint(new Vector3f(j[k].Position.X + dx, j[k].Position.Y, j[k].Position.Z), j[k].TrackingState);
                ctx.PushSkeleton(j, Layout.Kinect2, SyntheticKinect2.Time(frame));
                ctx.Step(1.0f / 30.0f);
            }
        }

        private static void SleepNow(Context ctx, ref int frame)
        {
            for (int i = 0; i < 300 && ctx.GetSkipStats().GarmentsAsleep == 0; ++i) StillFrames(ctx, ref frame, 1);
            Assert.Equal(1u, ctx.GetSkipStats().GarmentsAsleep);
        }

        [Fact]
        public void DefaultsAndRoundTrip()
        {
            PipelineOptions d = PipelineOptions.CreateDefault();
            Assert.Equal(1u, d.CullProxies);
            Assert.Equal(1u, d.StagesOnDemand);
            Assert.Equal(1u, d.Sleep);
            Assert.Equal(0.5f, d.SleepDelayS);
            Assert.Equal(0.005f, d.SleepDistanceM);
            Assert.Equal(0.02f, d.SleepSpeedMS);
            Assert.Equal(0.1f, d.ReachMarginM);
            using var ctx = new Context();
            Assert.Equal(d, ctx.PipelineOptions);
            PipelineOptions full = PipelineOptions.CreateFull();
            ctx.PipelineOptions = full;
            Assert.Equal(full, ctx.PipelineOptions);
        }

        [Fact]
        public void BadOptionsAreRejectedAndChangeNothing()
        {
            using var ctx = new Context();
            PipelineOptions before = ctx.PipelineOptions;
            PipelineOptions bad = before;
            bad.SleepDelayS = float.NaN;
            var e = Assert.Throws<DrapeException>(() => ctx.PipelineOptions = bad);
            Assert.Equal(ResultCode.NonFinite, e.Code);
            bad = before;
            bad.Sleep = 2;
            e = Assert.Throws<DrapeException>(() => ctx.PipelineOptions = bad);
            Assert.Equal(ResultCode.OutOfRange, e.Code);
            bad = before;
            bad.StructSize = 0;
            e = Assert.Throws<DrapeException>(() => ctx.PipelineOptions = bad);
            Assert.Equal(ResultCode.InvalidArgument, e.Code);
            Assert.Equal(before, ctx.PipelineOptions);
        }

        [Fact]
        public void GarmentSleepsOnAStillPoseAndWakes()
        {
            using var ctx = new Context();
            GarmentTemplate t = GarmentTemplate.CreateDefault(GarmentKind.Skirt);
            t.Particles = 400;
            using Garment g = ctx.AddGarment(t);
            int frame = 0;
            StillFrames(ctx, ref frame, 1);
            SkipStats s = ctx.GetSkipStats();
            Assert.Equal(1u, s.Garments);
            Assert.True(s.ProxiesBuilt > 0 && s.ProxiesBuilt < s.ProxiesAvailable, "a skirt world culls ellipsoids");
            Assert.True(s.LastSkipped.HasFlag(PipelineStage.BodyMesh));

            SleepNow(ctx, ref frame);
            ulong steps = g.Stats.Steps;
            StillFrames(ctx, ref frame, 3);
            Assert.Equal(steps, g.Stats.Steps);
            s = ctx.GetSkipStats();
            Assert.True(s.FramesSlept >= 3);
            Assert.True(s.LastSkipped.HasFlag(PipelineStage.Cloth));

            ClothParams p = g.Params;
            p.Damping = 2.0f;
            g.Params = p;  // new parameters wake it
            StillFrames(ctx, ref frame, 1);
            Assert.Equal(steps + 1, g.Stats.Steps);

            SleepNow(ctx, ref frame);
            steps = g.Stats.Steps;
            ctx.Wake();
            StillFrames(ctx, ref frame, 1);
            Assert.Equal(steps + 1, g.Stats.Steps);

            SleepNow(ctx, ref frame);
            steps = g.Stats.Steps;
            StillFrames(ctx, ref frame, 1, 0.3f);  // the body moves: it steps that frame
            Assert.Equal(steps + 1, g.Stats.Steps);
            Assert.Equal(0u, ctx.GetSkipStats().GarmentsAsleep);
        }
    }
}
