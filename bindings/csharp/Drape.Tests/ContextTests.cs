using System;
using System.Runtime.CompilerServices;
using Xunit;

namespace Drape.Tests
{
    /// <summary>Context lifetime, body shape, the pipeline on synthetic frames and error paths.
    /// Needs only the native library (no shared data).</summary>
    public class ContextTests
    {
        public ContextTests() => TestEnvironment.RequireNativeLibrary();

        /// <summary>Pushes and updates frames 0..count-1 of the synthetic sequence.</summary>
        internal static void Run(Context ctx, int count, int first = 0)
        {
            for (int i = first; i < first + count; ++i)
            {
                ctx.PushSkeleton(SyntheticKinect2.Frame(i), Layout.Kinect2, SyntheticKinect2.Time(i));
                ctx.Update();
            }
        }

        /// <summary>Reads the whole mesh and checks it: sizes as queried, every number finite,
        /// unit normals, indices in range and whole triangles.</summary>
        internal static (Vector3f[] Positions, Vector3f[] Normals, uint[] Indices) ReadAndCheckMesh(Context ctx)
        {
            var (vertexCount, indexCount) = ctx.GetBodyMeshSize();
            Assert.True(vertexCount > 0 && indexCount > 0);
            Assert.Equal(0, indexCount % 3);
            var positions = new Vector3f[vertexCount];
            var normals = new Vector3f[vertexCount];
            var indices = new uint[indexCount];
            ctx.ReadBodyMesh(positions, normals, indices);
            for (int i = 0; i < vertexCount; ++i)
            {
                Assert.True(positions[i].IsFinite, $"position {i} = {positions[i]}");
                Assert.True(normals[i].IsFinite, $"normal {i} = {normals[i]}");
                float len = MathF.Sqrt(normals[i].X * normals[i].X + normals[i].Y * normals[i].Y + normals[i].Z * normals[i].Z);
                Assert.InRange(len, 0.99f, 1.01f);
            }
            foreach (uint index in indices) Assert.True(index < (uint)vertexCount, $"index {index} >= {vertexCount}");
            return (positions, normals, indices);
        }

        [Fact]
        public void CreateAndDispose_TwiceIsHarmless()
        {
            var ctx = new Context();
            Assert.NotEqual(IntPtr.Zero, ctx.Handle);
            Assert.False(ctx.IsDisposed);
            ctx.Dispose();
            Assert.True(ctx.IsDisposed);
            Assert.Equal(IntPtr.Zero, ctx.Handle);
            ctx.Dispose();
        }

        [Fact]
        public void ContextDesc_Defaults_AndACustomRingCountChangesTheMesh()
        {
            ContextDesc d = ContextDesc.CreateDefault();
            Assert.Equal(72u, d.StructSize);
            Assert.Equal(20u, d.RingPoints);
            Assert.True(d.IsArmsClearTorso);
            Assert.Equal(0.01f, d.ArmTorsoClearanceM);
            Assert.Equal(1u, d.RingsPerSegment);
            Assert.Equal(30u, d.CalibrationFrames);
            Assert.Equal(Filter.OneEuro, d.Filter);
            Assert.Equal(ProxyRule.Drape, d.ProxyRule);
            Assert.Equal(GarmentFit.Shape, d.GarmentFit);
            using var standard = new Context(d);
            d.RingPoints = 32;
            using var finer = new Context(d);
            Assert.True(finer.GetBodyMeshSize().VertexCount > standard.GetBodyMeshSize().VertexCount);
        }

        [Fact]
        public void ContextDesc_ArmsClearTorso_MovesOnlyTheArmEllipsoids()
        {
            Ellipsoid[] After(ContextDesc desc)
            {
                using var ctx = new Context(desc);
                Run(ctx, 3);
                var e = new Ellipsoid[ctx.GetEllipsoidCount()];
                Assert.Equal(e.Length, ctx.ReadEllipsoids(e));
                return e;
            }
            ContextDesc d = ContextDesc.CreateDefault();
            Ellipsoid[] clear = After(d);
            d.IsArmsClearTorso = false;
            Ellipsoid[] onBones = After(d);
            Assert.Equal(clear.Length, onBones.Length);
            float moved = 0f;
            for (int k = 0; k < clear.Length; ++k)
            {
                var a = clear[k].Centre;
                var b = onBones[k].Centre;
                float dist = MathF.Sqrt((a.X - b.X) * (a.X - b.X) + (a.Y - b.Y) * (a.Y - b.Y) + (a.Z - b.Z) * (a.Z - b.Z));
                if (clear[k].Chain == 2 || clear[k].Chain == 3) moved = MathF.Max(moved, dist);
                else Assert.Equal(0f, dist);  // torso, head and legs stay where they were
            }
            Assert.True(moved > 0.002f, $"the arms hang against the torso: some arm ellipsoid moves ({moved} m)");
        }

        [Fact]
        public void ContextDesc_Invalid_Throws()
        {
            ContextDesc d = ContextDesc.CreateDefault();
            d.RingPoints = 10;
            var e = Assert.Throws<DrapeException>(() => new Context(d));
            Assert.Equal(ResultCode.OutOfRange, e.Code);
            Assert.Contains("ring_points", e.NativeMessage);

            d = ContextDesc.CreateDefault();
            d.GarmentFit = (GarmentFit)2;
            e = Assert.Throws<DrapeException>(() => new Context(d));
            Assert.Equal(ResultCode.OutOfRange, e.Code);
            Assert.Contains("garment_fit", e.NativeMessage);
            d.GarmentFit = GarmentFit.Skeleton;
            using (new Context(d)) { }

            d = ContextDesc.CreateDefault();
            d.ArmTorsoClearanceM = 0.06f;
            e = Assert.Throws<DrapeException>(() => new Context(d));
            Assert.Equal(ResultCode.OutOfRange, e.Code);
            Assert.Contains("arm_torso_clearance_m", e.NativeMessage);
            d.ArmTorsoClearanceM = float.NaN;
            e = Assert.Throws<DrapeException>(() => new Context(d));
            Assert.Equal(ResultCode.NonFinite, e.Code);
            d = ContextDesc.CreateDefault();
            d.ArmsClearTorso = 2;
            e = Assert.Throws<DrapeException>(() => new Context(d));
            Assert.Equal(ResultCode.OutOfRange, e.Code);
            Assert.Contains("arms_clear_torso", e.NativeMessage);

            e = Assert.Throws<DrapeException>(() => new Context(default(ContextDesc)));  // struct_size 0
            Assert.Equal(ResultCode.InvalidArgument, e.Code);
            Assert.Contains("struct_size", e.Message);
        }

        [Fact]
        public void DisposedContext_ThrowsObjectDisposed_BeforeAnyNativeCall()
        {
            var ctx = new Context();
            ctx.Dispose();
            var joints = SyntheticKinect2.Frame(0);
            BodyShape shape = BodyShape.CreateDefault();
            Assert.Throws<ObjectDisposedException>(() => ctx.SetBodyShape(shape));
            Assert.Throws<ObjectDisposedException>(() => ctx.GetBodyShape());
            Assert.Throws<ObjectDisposedException>(() => ctx.PushSkeleton(joints, Layout.Kinect2, 0.0));
            Assert.Throws<ObjectDisposedException>(() => ctx.Update());
            Assert.Throws<ObjectDisposedException>(() => ctx.GetBodyMeshSize());
            Assert.Throws<ObjectDisposedException>(() => ctx.ReadBodyMesh(new Vector3f[1], default, default));
            Assert.Throws<ObjectDisposedException>(() => ctx.ReadSkeleton(new Vector3f[21]));
            Assert.Throws<ObjectDisposedException>(() => ctx.GetFrameStats());
        }

        [Fact]
        public void BodyShape_Defaults_ArePredictedByTheContext()
        {
            BodyShape s = BodyShape.CreateDefault();
            Assert.Equal(48u, s.StructSize);
            Assert.Equal(Sex.Unspecified, s.Sex);
            Assert.Equal(1.70f, s.HeightM);
            Assert.Equal(65f, s.WeightKg);
            Assert.Equal(0f, s.ChestMm);  // 0 = predict

            using var ctx = new Context();
            BodyShape r = ctx.GetBodyShape();
            Assert.Equal(48u, r.StructSize);
            Assert.Equal(1.70f, r.HeightM);
            Assert.Equal(65f, r.WeightKg);
            foreach (float g in new[] { r.NeckMm, r.ChestMm, r.WaistMm, r.HipMm, r.ThighMm, r.CalfMm, r.UpperArmMm, r.ForearmMm })
                Assert.InRange(g, 100f, 1500f);
        }

        [Fact]
        public void BodyShape_SetThenGet_GivenGirthsComeBackAsGiven()
        {
            using var ctx = new Context();
            BodyShape s = BodyShape.CreateDefault();
            s.Sex = Sex.Female;
            s.HeightM = 1.62f;
            s.WeightKg = 58f;
            s.ChestMm = 880f;
            s.WaistMm = 700f;
            s.HipMm = 960f;
            s.ForearmMm = 233.3f;
            ctx.SetBodyShape(s);

            BodyShape r = ctx.GetBodyShape();
            Assert.Equal(Sex.Female, r.Sex);
            Assert.Equal(1.62f, r.HeightM);
            Assert.Equal(58f, r.WeightKg);
            // The library stores girths in metres (mm * 0.001f) and reports mm * 1000f: allow the float round trip.
            Assert.Equal(880f, r.ChestMm, 0.001f);
            Assert.Equal(700f, r.WaistMm, 0.001f);
            Assert.Equal(960f, r.HipMm, 0.001f);
            Assert.Equal(233.3f, r.ForearmMm, 0.001f);
            foreach (float g in new[] { r.NeckMm, r.ThighMm, r.CalfMm, r.UpperArmMm })  // predicted
                Assert.InRange(g, 100f, 1500f);
        }

        [Fact]
        public void BodyShape_NaNHeight_ThrowsNonFinite_AndKeepsTheShape()
        {
            using var ctx = new Context();
            BodyShape before = ctx.GetBodyShape();
            BodyShape s = BodyShape.CreateDefault();
            s.HeightM = float.NaN;
            var e = Assert.Throws<DrapeException>(() => ctx.SetBodyShape(s));
            Assert.Equal(ResultCode.NonFinite, e.Code);
            Assert.Contains("height", e.NativeMessage);
            Assert.Contains("height", e.Message);
            Assert.Equal(before, ctx.GetBodyShape());
        }

        [Fact]
        public void BodyShape_OutOfRange_AndUninitialised_Throw()
        {
            using var ctx = new Context();
            BodyShape s = BodyShape.CreateDefault();
            s.HeightM = 3.0f;
            Assert.Equal(ResultCode.OutOfRange, Assert.Throws<DrapeException>(() => ctx.SetBodyShape(s)).Code);
            s = BodyShape.CreateDefault();
            s.WaistMm = 10f;
            Assert.Equal(ResultCode.OutOfRange, Assert.Throws<DrapeException>(() => ctx.SetBodyShape(s)).Code);
            s = BodyShape.CreateDefault();
            s.Sex = (Sex)7;
            Assert.Equal(ResultCode.OutOfRange, Assert.Throws<DrapeException>(() => ctx.SetBodyShape(s)).Code);
            s = default;  // struct_size 0: not initialised with CreateDefault
            s.HeightM = 1.7f;
            s.WeightKg = 60f;
            Assert.Equal(ResultCode.InvalidArgument, Assert.Throws<DrapeException>(() => ctx.SetBodyShape(s)).Code);
        }

        [Fact]
        public void BeforeTheFirstUpdate_IndicesAreReadable_PositionsAreCallOrder()
        {
            using var ctx = new Context();
            Assert.Equal(ResultCode.CallOrder, Assert.Throws<DrapeException>(() => ctx.Update()).Code);
            var (v, n) = ctx.GetBodyMeshSize();
            var indices = new uint[n];
            ctx.ReadBodyMesh(default, default, indices);
            Assert.All(indices, i => Assert.True(i < (uint)v));
            var e = Assert.Throws<DrapeException>(() => ctx.ReadBodyMesh(new Vector3f[v], default, default));
            Assert.Equal(ResultCode.CallOrder, e.Code);
        }

        [Fact]
        public void SyntheticFrames_PushUpdate_MeshIsFiniteAndStatsCount()
        {
            using var ctx = new Context();
            Run(ctx, 40);
            ReadAndCheckMesh(ctx);
            FrameStats s = ctx.GetFrameStats();
            Assert.Equal(72u, s.StructSize);
            Assert.Equal(40u, s.FramesPushed);
            Assert.Equal(40u, s.FramesAccepted);
            Assert.Equal(0u, s.FramesRejected);
            Assert.Equal(40u, s.Updates);
            Assert.True(s.IsCalibrated);  // 30 calibration frames by default
            Assert.Equal(SyntheticKinect2.Time(39), s.LastTimestampS);
            Assert.True(float.IsFinite(s.BodyVolumeL) && s.BodyVolumeL > 10f, $"volume {s.BodyVolumeL} L");

            var skeleton = new Vector3f[21];
            Assert.Equal(21, ctx.ReadSkeleton(skeleton));
            Assert.All(skeleton, p => Assert.True(p.IsFinite));
        }

        [Fact]
        public void Ellipsoids_AfterUpdates_AreFiniteAndMatchTheirMatrices()
        {
            using var ctx = new Context();
            int n = ctx.GetEllipsoidCount();
            Assert.True(n > 20, $"{n} ellipsoids");
            var early = new Ellipsoid[n];
            var e = Assert.Throws<DrapeException>(() => ctx.ReadEllipsoids(early));
            Assert.Equal(ResultCode.CallOrder, e.Code);

            Run(ctx, 40);
            var ellipsoids = new Ellipsoid[n];
            Assert.Equal(n, ctx.ReadEllipsoids(ellipsoids));
            var matrices = new float[16 * n];
            Assert.Equal(n, ctx.ReadEllipsoidMatrices(matrices));
            for (int i = 0; i < n; ++i)
            {
                Ellipsoid el = ellipsoids[i];
                Assert.True(el.Radii.X > 0 && el.Radii.Y > 0 && el.Radii.Z > 0, $"ellipsoid {i} radii {el.Radii}");
                Assert.True(el.Centre.IsFinite);
                // Column 1 of M = AxisY * Radii.Y; column 3 = centre.
                Assert.Equal(el.AxisY.X * el.Radii.Y, matrices[16 * i + 4], 4);
                Assert.Equal(el.Centre.Z, matrices[16 * i + 14], 4);
            }
            var small = new Ellipsoid[n - 1];
            Assert.Equal(ResultCode.BufferTooSmall, Assert.Throws<DrapeException>(() => ctx.ReadEllipsoids(small)).Code);

            ProxyFidelity f = ctx.MeasureProxyFidelity();
            Assert.Equal(40u, f.StructSize);
            Assert.True(f.UnionSamples > 0);
            Assert.True(f.BodyToProxyP95Mm >= 0 && f.BodyToProxyP95Mm < 30, $"body->proxy P95 {f.BodyToProxyP95Mm} mm");
            Assert.True(f.ProxyToBodyP95Mm >= 0 && f.ProxyToBodyP95Mm < 30, $"proxy->body P95 {f.ProxyToBodyP95Mm} mm");
        }

        [Fact]
        public void TooSmallSpans_ThrowBufferTooSmall_AndWriteNothing()
        {
            using var ctx = new Context();
            Run(ctx, 3);
            var (v, n) = ctx.GetBodyMeshSize();
            var sentinel = new Vector3f(-7f, -7f, -7f);
            var positions = new Vector3f[v - 1];
            Array.Fill(positions, sentinel);
            var e = Assert.Throws<DrapeException>(() => ctx.ReadBodyMesh(positions, default, default));
            Assert.Equal(ResultCode.BufferTooSmall, e.Code);
            Assert.All(positions, p => Assert.Equal(sentinel, p));

            // Normals long enough but positions one short: the shorter one decides.
            e = Assert.Throws<DrapeException>(() => ctx.ReadBodyMesh(positions, new Vector3f[v], default));
            Assert.Equal(ResultCode.BufferTooSmall, e.Code);

            var indices = new uint[n - 1];
            Array.Fill(indices, 12345u);
            var fullPositions = new Vector3f[v];
            Array.Fill(fullPositions, sentinel);
            e = Assert.Throws<DrapeException>(() => ctx.ReadBodyMesh(fullPositions, default, indices));
            Assert.Equal(ResultCode.BufferTooSmall, e.Code);
            Assert.All(indices, i => Assert.Equal(12345u, i));
            Assert.All(fullPositions, p => Assert.Equal(sentinel, p));  // nothing written, not even the part that fit

            Assert.Equal(ResultCode.BufferTooSmall,
                         Assert.Throws<DrapeException>(() => ctx.ReadSkeleton(new Vector3f[20])).Code);
            Assert.Equal(ResultCode.NullArgument,
                         Assert.Throws<DrapeException>(() => ctx.ReadBodyMesh(default, default, default)).Code);
        }

        [Fact]
        public void NaNJoint_ThrowsNonFinite_AndTheContextKeepsWorking()
        {
            using var ctx = new Context();
            Run(ctx, 5);
            var (before, _, _) = ReadAndCheckMesh(ctx);

            Joint[] bad = SyntheticKinect2.Frame(5);
            bad[7].Position.Y = float.NaN;
            var e = Assert.Throws<DrapeException>(() => ctx.PushSkeleton(bad, Layout.Kinect2, SyntheticKinect2.Time(5)));
            Assert.Equal(ResultCode.NonFinite, e.Code);
            Assert.Contains("joint 7", e.NativeMessage);

            bad[7].Position.Y = float.PositiveInfinity;
            Assert.Equal(ResultCode.NonFinite,
                         Assert.Throws<DrapeException>(() => ctx.PushSkeleton(bad, Layout.Kinect2, SyntheticKinect2.Time(5))).Code);

            // Nothing changed: an update without a new frame leaves the mesh as it was.
            ctx.Update();
            var (after, _, _) = ReadAndCheckMesh(ctx);
            Assert.Equal(before, after);
            FrameStats s = ctx.GetFrameStats();
            Assert.Equal(2u, s.FramesRejected);
            Assert.Equal(5u, s.FramesAccepted);

            // And it goes on: the same timestamp is still free.
            Run(ctx, 5, first: 5);
            ReadAndCheckMesh(ctx);
            Assert.Equal(10u, ctx.GetFrameStats().FramesAccepted);
        }

        [Fact]
        public void BadFrames_ThrowTheDocumentedCodes()
        {
            using var ctx = new Context();
            Run(ctx, 2);
            Joint[] ok = SyntheticKinect2.Frame(2);
            double t = SyntheticKinect2.Time(2);

            Assert.Equal(ResultCode.Timestamp,
                Assert.Throws<DrapeException>(() => ctx.PushSkeleton(ok, Layout.Kinect2, SyntheticKinect2.Time(1))).Code);
            Assert.Equal(ResultCode.InvalidArgument,
                Assert.Throws<DrapeException>(() => ctx.PushSkeleton(ok.AsSpan(0, 24), Layout.Kinect2, t)).Code);
            Assert.Equal(ResultCode.OutOfRange,
                Assert.Throws<DrapeException>(() => ctx.PushSkeleton(ok, (Layout)9, t)).Code);
            Assert.Equal(ResultCode.OutOfRange,
                Assert.Throws<DrapeException>(() => ctx.PushSkeleton(ok, Layout.Auto, t)).Code);
            Assert.Equal(ResultCode.NonFinite,
                Assert.Throws<DrapeException>(() => ctx.PushSkeleton(ok, Layout.Kinect2, double.NaN)).Code);
            // An empty span is joint_count 0 (checked before the NULL pointer).
            Assert.Equal(ResultCode.InvalidArgument,
                Assert.Throws<DrapeException>(() => ctx.PushSkeleton(ReadOnlySpan<Joint>.Empty, Layout.Kinect2, t)).Code);

            // Orientations: managed length check, then the library's unit-length check.
            Assert.Throws<ArgumentException>(() => ctx.PushSkeleton(ok, Layout.Kinect2, t, new Quaternionf[3]));
            Assert.Equal(ResultCode.InvalidArgument,
                Assert.Throws<DrapeException>(() => ctx.PushSkeleton(ok, Layout.Kinect2, t, new Quaternionf[25])).Code);
            var identity = new Quaternionf[25];
            Array.Fill(identity, Quaternionf.Identity);
            ctx.PushSkeleton(ok, Layout.Kinect2, t, identity);
            ctx.Update();

            Assert.Equal(7u, ctx.GetFrameStats().FramesRejected);
        }

        [MethodImpl(MethodImplOptions.NoInlining)]
        private static void CreateAndForget() => _ = new Context();

        [Fact]
        public void UndisposedContext_IsReportedAsALeak_NotFreedOnTheFinalizerThread()
        {
            int reported = 0;
            void OnLeak(string message)
            {
                if (message.Contains("Context")) System.Threading.Interlocked.Increment(ref reported);
            }
            long before = DrapeLibrary.LeakedHandleCount;
            DrapeLibrary.HandleLeaked += OnLeak;
            try
            {
                CreateAndForget();
                for (int i = 0; i < 5 && DrapeLibrary.LeakedHandleCount == before; ++i)
                {
                    GC.Collect();
                    GC.WaitForPendingFinalizers();
                }
            }
            finally
            {
                DrapeLibrary.HandleLeaked -= OnLeak;
            }
            Assert.True(DrapeLibrary.LeakedHandleCount > before);
            Assert.True(reported >= 1);
        }
    }
}
