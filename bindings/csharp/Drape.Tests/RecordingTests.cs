using System;
using System.IO;
using Xunit;
using Xunit.Abstractions;

namespace Drape.Tests
{
    /// <summary>The native Recording API, on synthetic data and on a real Kinect v2 capture from
    /// the shared data folder.</summary>
    public class RecordingTests
    {
        private readonly ITestOutputHelper _output;

        public RecordingTests(ITestOutputHelper output)
        {
            _output = output;
            TestEnvironment.RequireNativeLibrary();
        }

        [Fact]
        public void SyntheticCsv_OpensFromMemory_ReadsBack_SavesAndReopens()
        {
            using var rec = Recording.OpenMemory(SyntheticKinect2.Csv(12));
            RecordingInfo info = rec.Info;
            Assert.Equal(32u, info.StructSize);
            Assert.Equal(RecordingFormat.KinectCsv, info.Format);
            Assert.Equal(Layout.Kinect2, info.Layout);
            Assert.Equal(25u, info.JointCount);
            Assert.Equal(12u, info.FrameCount);
            Assert.InRange(info.NominalRateHz, 29.9f, 30.1f);
            Assert.Equal(11 / 30.0, info.DurationS, 1e-6);

            var joints = new Joint[25];
            rec.ReadFrame(4, joints, out double t);
            Assert.Equal(4 / 30.0, t, 1e-6);
            Assert.Equal(SyntheticKinect2.Frame(4), joints);

            string path = Path.Combine(Path.GetTempPath(), $"drape-cs-{Guid.NewGuid():N}.drape");
            try
            {
                rec.Save(path);
                using var again = Recording.Open(path);
                Assert.Equal(RecordingFormat.Drape, again.Info.Format);
                Assert.Equal(12u, again.Info.FrameCount);
                var joints2 = new Joint[25];
                again.ReadFrame(4, joints2, out double t2);
                Assert.Equal(t, t2, 1e-6);
                for (int j = 0; j < 25; ++j)
                {
                    Assert.Equal(joints[j].TrackingState, joints2[j].TrackingState);
                    Assert.Equal(joints[j].Position.X, joints2[j].Position.X, 1e-5f);
                    Assert.Equal(joints[j].Position.Y, joints2[j].Position.Y, 1e-5f);
                    Assert.Equal(joints[j].Position.Z, joints2[j].Position.Z, 1e-5f);
                }
            }
            finally
            {
                File.Delete(path);
            }
        }

        [Fact]
        public void RecordingErrors_HaveTheDocumentedCodes()
        {
            string missing = Path.Combine(Path.GetTempPath(), $"drape-cs-missing-{Guid.NewGuid():N}.csv");
            var e = Assert.Throws<DrapeException>(() => Recording.Open(missing));
            Assert.Equal(ResultCode.Io, e.Code);
            Assert.Contains(missing, e.NativeMessage);  // the UTF-8 path arrived intact

            Assert.Equal(ResultCode.Parse,
                Assert.Throws<DrapeException>(() => Recording.OpenMemory("not a recording\n"u8)).Code);
            Assert.Equal(ResultCode.Parse,
                Assert.Throws<DrapeException>(() => Recording.OpenMemory(SyntheticKinect2.Csv(3), Layout.Kinect1)).Code);
            Assert.Equal(ResultCode.OutOfRange,
                Assert.Throws<DrapeException>(() => Recording.OpenMemory(SyntheticKinect2.Csv(3), (Layout)9)).Code);
            Assert.Throws<ArgumentException>(() => Recording.Open("bad\0path"));

            var rec = Recording.OpenMemory(SyntheticKinect2.Csv(3));
            var joints = new Joint[25];
            Assert.Equal(ResultCode.OutOfRange,
                Assert.Throws<DrapeException>(() => rec.ReadFrame(3, joints, out _)).Code);
            Assert.Throws<ArgumentOutOfRangeException>(() => rec.ReadFrame(-1, joints, out _));
            Assert.Equal(ResultCode.BufferTooSmall,
                Assert.Throws<DrapeException>(() => rec.ReadFrame(0, new Joint[24], out _)).Code);
            rec.Dispose();
            rec.Dispose();
            Assert.Throws<ObjectDisposedException>(() => rec.ReadFrame(0, joints, out _));
            Assert.Throws<ObjectDisposedException>(() => rec.Save(missing));
        }

        /// <summary>
        /// The real thing: every frame of a Microsoft Labanotation Kinect v2 capture
        /// (shared/data/kinect_v2_msft_labanotation/Ges01_wavehand.csv), read with the native
        /// Recording API, pushed and updated; the mesh is checked after every update.
        /// SKIPS (passes, with a "SKIPPED" line in the test output) when the shared data folder is
        /// absent: xunit 2 has no dynamic skip. Set DRAPE_SHARED_DATA to point at shared/data.
        /// </summary>
        [Fact]
        public void KinectV2WaveHand_EveryFrame_PushUpdateRead_AllFinite_OrSkippedWithoutSharedData()
        {
            string? path = TestEnvironment.SharedFile("kinect_v2_msft_labanotation/Ges01_wavehand.csv", out string why);
            if (path == null)
            {
                _output.WriteLine($"SKIPPED: {why}. Set DRAPE_SHARED_DATA to the shared/data folder to run this test.");
                return;
            }

            using var rec = Recording.Open(path);
            RecordingInfo info = rec.Info;
            Assert.Equal(RecordingFormat.KinectCsv, info.Format);
            Assert.Equal(Layout.Kinect2, info.Layout);
            Assert.Equal(25u, info.JointCount);
            Assert.True(info.FrameCount > 100, $"{info.FrameCount} frames");
            Assert.InRange(info.NominalRateHz, 10f, 60f);
            _output.WriteLine($"{Path.GetFileName(path)}: {info.FrameCount} frames, {info.NominalRateHz:F1} Hz, {info.DurationS:F2} s");

            using var ctx = new Context();
            var joints = new Joint[info.JointCount];
            double last = double.NaN;
            for (int i = 0; i < (int)info.FrameCount; ++i)
            {
                rec.ReadFrame(i, joints, out last);
                ctx.PushSkeleton(joints, info.Layout, last);
                ctx.Update();
                ContextTests.ReadAndCheckMesh(ctx);
            }

            FrameStats s = ctx.GetFrameStats();
            Assert.Equal(info.FrameCount, s.FramesAccepted);
            Assert.Equal(0u, s.FramesRejected);
            Assert.Equal(info.FrameCount, s.Updates);
            Assert.True(s.IsCalibrated);
            Assert.Equal(last, s.LastTimestampS);
            Assert.Equal(info.DurationS, last, 1e-6);
            Assert.InRange(s.BodyVolumeL, 20f, 200f);
            _output.WriteLine($"body volume {s.BodyVolumeL:F1} L, last update: skeleton {s.SkeletonMs:F3} ms, body {s.BodyMs:F3} ms, teleports {s.Teleports}");
        }
    }
}
