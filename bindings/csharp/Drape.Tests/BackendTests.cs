using System;
using Xunit;

namespace Drape.Tests
{
    /// <summary>The Backends section through C#: defaults, the device list, a rejected desc, the
    /// fallback with its reason, and a garment stepping on OpenCL when the machine has a device
    /// (PoCL in CI). docs/opencl.md.</summary>
    public class BackendTests
    {
        public BackendTests() => TestEnvironment.RequireNativeLibrary();

        private static void StepFrames(Context ctx, int count)
        {
            for (int i = 0; i < count; ++i)
            {
                ctx.PushSkeleton(SyntheticKinect2.Frame(i), Layout.Kinect2, SyntheticKinect2.Time(i));
                ctx.Step(1.0f / 30.0f);
            }
        }

        [Fact]
        public void DefaultsAndCpuStart()
        {
            BackendDesc d = BackendDesc.CreateDefault();
            Assert.Equal(Backend.Cpu, d.Backend);
            Assert.Equal(-1, d.PlatformIndex);
            Assert.Equal(-1, d.DeviceIndex);
            Assert.Equal(1u, d.PreferGpu);
            Assert.Equal(2000u, d.OpenclMinParticles);
            using var ctx = new Context();
            BackendStatus s = ctx.GetBackendInfo();
            Assert.Equal(Backend.Cpu, s.Active);
            Assert.Equal("", s.FallbackReason);
        }

        [Fact]
        public void BadDescIsRejected()
        {
            using var ctx = new Context();
            BackendDesc d = BackendDesc.CreateDefault();
            d.Backend = (Backend)7;
            var e = Assert.Throws<DrapeException>(() => ctx.SetBackend(d));
            Assert.Equal(ResultCode.OutOfRange, e.Code);
            Assert.Equal(Backend.Cpu, ctx.GetBackendInfo().Requested);
        }

        [Fact]
        public void ImpossibleDeviceFallsBackToTheCpu()
        {
            using var ctx = new Context();
            BackendDesc d = BackendDesc.CreateDefault();
            d.Backend = Backend.OpenCl;
            d.DeviceIndex = 250;
            ctx.SetBackend(d);
            BackendStatus s = ctx.GetBackendInfo();
            Assert.Equal(Backend.OpenCl, s.Requested);
            Assert.Equal(Backend.Cpu, s.Active);
            Assert.NotEqual("", s.FallbackReason);
        }

        private static (Context, Garment) Person(Backend backend)
        {
            var ctx = new Context();
            GarmentTemplate t = GarmentTemplate.CreateDefault(GarmentKind.TShirt);
            t.Particles = 400;
            Garment g = ctx.AddGarment(t);
            BackendDesc d = BackendDesc.CreateDefault();
            d.Backend = backend;
            ctx.SetBackend(d);
            return (ctx, g);
        }

        [Fact]
        public void StepAllMatchesSteppingEachContext()
        {
            // On the device when there is one (batched launches), else on the CPU: the same either way.
            var (a, ga) = Person(Backend.OpenCl);
            var (b, gb) = Person(Backend.OpenCl);
            var (c, gc) = Person(Backend.OpenCl);
            var (d, gd) = Person(Backend.OpenCl);
            using (a) using (b) using (c) using (d)
            {
                for (int i = 0; i < 4; ++i)
                {
                    foreach (Context x in new[] { a, b, c, d })
                        x.PushSkeleton(SyntheticKinect2.Frame(i), Layout.Kinect2, SyntheticKinect2.Time(i));
                    Context.StepAll(new[] { a, b }, 1.0f / 30.0f);
                    c.Step(1.0f / 30.0f);
                    d.Step(1.0f / 30.0f);
                }
                Assert.Equal(gc.ViewPositions().ToArray(), ga.ViewPositions().ToArray());
                Assert.Equal(gd.ViewPositions().ToArray(), gb.ViewPositions().ToArray());
                Assert.Equal(4ul, ga.Stats.Steps);

                // Rejected calls step nothing.
                float[] before = ga.ViewPositions().ToArray();
                Assert.Throws<ArgumentNullException>(() => Context.StepAll(null!, 1.0f / 30.0f));
                Assert.Throws<ArgumentNullException>(() => Context.StepAll(new Context[] { a, null! }, 1.0f / 30.0f));
                Assert.Equal(ResultCode.OutOfRange,
                    Assert.Throws<DrapeException>(() => Context.StepAll(Array.Empty<Context>(), 1.0f / 30.0f)).Code);
                Assert.Equal(ResultCode.InvalidArgument,
                    Assert.Throws<DrapeException>(() => Context.StepAll(new[] { a, b, a }, 1.0f / 30.0f)).Code);
                Assert.Equal(ResultCode.NonFinite,
                    Assert.Throws<DrapeException>(() => Context.StepAll(new[] { a, b }, float.NaN)).Code);
                using var fresh = new Context();  // no skeleton frame yet
                Assert.Equal(ResultCode.CallOrder,
                    Assert.Throws<DrapeException>(() => Context.StepAll(new[] { a, fresh }, 1.0f / 30.0f)).Code);
                Assert.Equal(before, ga.ViewPositions().ToArray());
                Assert.Equal(4ul, ga.Stats.Steps);
            }
        }

        [Fact]
        public void GarmentStepsOnOpenClWhenADeviceExists()
        {
            var devices = OpenCl.Devices();
            foreach (OpenClDevice dev in devices) Assert.NotEqual("", dev.DeviceName);
            if (devices.Count == 0) return;  // no OpenCL driver: nothing more to check here
            using var ctx = new Context();
            GarmentTemplate t = GarmentTemplate.CreateDefault(GarmentKind.TShirt);
            t.Particles = 400;
            Garment g = ctx.AddGarment(t);
            BackendDesc d = BackendDesc.CreateDefault();
            d.Backend = Backend.OpenCl;
            ctx.SetBackend(d);
            BackendStatus s = ctx.GetBackendInfo();
            if (s.Active != Backend.OpenCl) return;  // the device could not build the kernels: reason in s
            Assert.Equal(1, s.OpenClGarments);
            Assert.NotEqual("", s.DeviceName);
            StepFrames(ctx, 4);
            Assert.True(g.Stats.Contacts > 0);
        }
    }
}
