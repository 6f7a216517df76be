using System;

namespace Drape
{
    /// <summary>
    /// One tracked person (drape_context): skeleton in, body mesh out.
    /// <para>Owns its native handle: call <see cref="Dispose"/> (or use <c>using</c>). Not
    /// thread-safe: one thread at a time, Dispose included (the C ABI's rule). Different
    /// contexts may be used on different threads at once.</para>
    /// <para>A context that is garbage-collected without Dispose is leaked, not freed: its
    /// finalizer calls no native code and only reports the leak
    /// (<see cref="DrapeLibrary.LeakedHandleCount"/>, <see cref="DrapeLibrary.HandleLeaked"/>).</para>
    /// </summary>
    public sealed unsafe class Context : IDisposable
    {
        private IntPtr _handle;

        /// <summary>Creates a context with the default settings.</summary>
        public Context()
        {
            DrapeLibrary.EnsureCompatible();
            IntPtr h;
            DrapeException.Check(Native.drape_context_create(null, &h));
            _handle = h;
        }

        /// <summary>Creates a context with <paramref name="desc"/>; start it from
        /// <see cref="ContextDesc.CreateDefault"/> (a zero StructSize is rejected).</summary>
        public Context(in ContextDesc desc)
        {
            DrapeLibrary.EnsureCompatible();
            IntPtr h;
            ContextDesc d = desc;
            DrapeException.Check(Native.drape_context_create(&d, &h));
            _handle = h;
        }

        /// <summary>The native drape_context* (for interop with other native code), or
        /// <see cref="IntPtr.Zero"/> once disposed. The context keeps ownership.</summary>
        public IntPtr Handle => _handle;

        /// <summary>True once <see cref="Dispose"/> has run.</summary>
        public bool IsDisposed => _handle == IntPtr.Zero;

        /// <summary>Destroys the native context (drape_context_destroy). Idempotent.</summary>
        public void Dispose()
        {
            IntPtr h = _handle;
            if (h == IntPtr.Zero) return;
            _handle = IntPtr.Zero;
            GC.SuppressFinalize(this);
            // Cannot fail for a handle this object created; nothing useful to do if it did.
            Native.drape_context_destroy(h);
        }

        /// <summary>Only reports the leak (see the class remarks); never calls native code.</summary>
        ~Context()
        {
            if (_handle != IntPtr.Zero) DrapeLibrary.ReportLeak(nameof(Context));
        }

        private IntPtr Live
        {
            get
            {
                IntPtr h = _handle;
                if (h == IntPtr.Zero) throw new ObjectDisposedException(nameof(Context));
                return h;
            }
        }

        // ---- Body shape --------------------------------------------------------------------------

        /// <summary>Sets the body shape (drape_context_set_body_shape); start from
        /// <see cref="BodyShape.CreateDefault"/>. On failure the previous shape is kept.</summary>
        public void SetBodyShape(in BodyShape shape)
        {
            IntPtr h = Live;
            BodyShape s = shape;
            DrapeException.Check(Native.drape_context_set_body_shape(h, &s));
        }

        /// <summary>The shape in use with every girth resolved (predicted ones filled in).</summary>
        public BodyShape GetBodyShape()
        {
            IntPtr h = Live;
            BodyShape s = default;
            s.StructSize = (uint)sizeof(BodyShape);
            DrapeException.Check(Native.drape_context_get_body_shape(h, &s));
            return s;
        }

        // ---- Skeleton ----------------------------------------------------------------------------

        /// <summary>Validates one sensor frame and queues it for the next <see cref="Update"/>
        /// (drape_context_push_skeleton). <paramref name="joints"/> must hold exactly the layout's
        /// joint count (Kinect1 20, Kinect2 25, Azure 32); timestamps must increase strictly.
        /// A rejected frame throws and leaves the context as it was (but for its statistics).</summary>
        public void PushSkeleton(ReadOnlySpan<Joint> joints, Layout layout, double timestampS) =>
            PushSkeleton(joints, layout, timestampS, ReadOnlySpan<Quaternionf>.Empty);

        /// <summary>As <see cref="PushSkeleton(ReadOnlySpan{Joint}, Layout, double)"/>, with one
        /// unit quaternion per joint (or an empty span for none).</summary>
        public void PushSkeleton(ReadOnlySpan<Joint> joints, Layout layout, double timestampS,
                                 ReadOnlySpan<Quaternionf> orientations)
        {
            IntPtr h = Live;
            if (!orientations.IsEmpty && orientations.Length != joints.Length)
                throw new ArgumentException(
                    $"orientations has {orientations.Length} entries; it must be empty or have one per joint ({joints.Length})",
                    nameof(orientations));
            fixed (Joint* pj = joints)
            fixed (Quaternionf* pq = orientations)
            {
                SkeletonFrame frame;
                frame.StructSize = (uint)sizeof(SkeletonFrame);
                frame.Layout = layout;
                frame.JointCount = (uint)joints.Length;
                frame.Reserved = 0;
                frame.TimestampS = timestampS;
                frame.Joints = pj;          // NULL for an empty span: the library rejects it
                frame.Orientations = pq;    // NULL for an empty span: none
                DrapeException.Check(Native.drape_context_push_skeleton(h, &frame));
            }
        }

        /// <summary>Runs the pipeline on the queued frame (drape_context_update). Throws
        /// <see cref="ResultCode.CallOrder"/> if no frame was ever accepted.</summary>
        public void Update()
        {
            IntPtr h = Live;
            DrapeException.Check(Native.drape_context_update(h));
        }

        /// <summary>Copies the filtered canonical skeleton (21 joints) after an update into
        /// <paramref name="positions"/>; returns the count written.</summary>
        public int ReadSkeleton(Span<Vector3f> positions)
        {
            IntPtr h = Live;
            uint count = 0;
            fixed (Vector3f* p = positions)
                DrapeException.Check(Native.drape_context_read_skeleton(h, p, (uint)positions.Length, &count));
            return (int)count;
        }

        // ---- Body mesh ---------------------------------------------------------------------------

        /// <summary>Vertex and index counts of the body mesh (fixed for the context's lifetime).</summary>
        public (int VertexCount, int IndexCount) GetBodyMeshSize()
        {
            IntPtr h = Live;
            uint vertices = 0, indices = 0;
            DrapeException.Check(Native.drape_context_get_body_mesh_size(h, &vertices, &indices));
            return ((int)vertices, (int)indices);
        }

        /// <summary>
        /// Copies the body mesh of the last update (drape_context_read_body_mesh). An empty span
        /// skips that array; at least one must be non-empty. Non-empty spans must be at least as
        /// long as <see cref="GetBodyMeshSize"/> says, else <see cref="ResultCode.BufferTooSmall"/>
        /// is thrown and nothing is written. Positions and normals need a successful update first
        /// (<see cref="ResultCode.CallOrder"/>); indices (counter-clockwise from outside, 3 per
        /// triangle) are available at once.
        /// </summary>
        public void ReadBodyMesh(Span<Vector3f> positions, Span<Vector3f> normals, Span<uint> indices)
        {
            IntPtr h = Live;
            // One vertex capacity covers both arrays: the shorter non-empty one.
            int vertexCapacity = positions.IsEmpty ? normals.Length
                : normals.IsEmpty ? positions.Length
                : Math.Min(positions.Length, normals.Length);
            fixed (Vector3f* pp = positions)
            fixed (Vector3f* pn = normals)
            fixed (uint* pi = indices)
            {
                DrapeException.Check(Native.drape_context_read_body_mesh(
                    h, pp, pn, (uint)vertexCapacity, pi, (uint)indices.Length));
            }
        }

        // ---- Statistics --------------------------------------------------------------------------

        /// <summary>Number of tracking ellipsoids (fixed for a context).</summary>
        public int GetEllipsoidCount()
        {
            IntPtr h = Live;
            uint n = 0;
            DrapeException.Check(Native.drape_context_get_ellipsoid_count(h, &n));
            return (int)n;
        }

        /// <summary>Copies the tracking ellipsoids of the last update; returns how many were written.</summary>
        public int ReadEllipsoids(Span<Ellipsoid> ellipsoids)
        {
            IntPtr h = Live;
            uint count = 0;
            fixed (Ellipsoid* p = ellipsoids)
                DrapeException.Check(Native.drape_context_read_ellipsoids(h, p, (uint)ellipsoids.Length, &count));
            return (int)count;
        }

        /// <summary>Copies the ellipsoids as 4x4 column-major matrices (16 floats each, unit sphere to
        /// ellipsoid); returns how many matrices were written.</summary>
        public int ReadEllipsoidMatrices(Span<float> matrices)
        {
            IntPtr h = Live;
            uint count = 0;
            fixed (float* p = matrices)
                DrapeException.Check(Native.drape_context_read_ellipsoid_matrices(h, p, (uint)(matrices.Length / 16), &count));
            return (int)count;
        }

        /// <summary>Measures how closely the ellipsoids follow the body mesh (a diagnostic, ~ms).</summary>
        public ProxyFidelity MeasureProxyFidelity()
        {
            IntPtr h = Live;
            ProxyFidelity f = default;
            f.StructSize = (uint)sizeof(ProxyFidelity);
            DrapeException.Check(Native.drape_context_measure_proxy_fidelity(h, &f));
            return f;
        }

        /// <summary>Counters and timings (drape_context_get_frame_stats).</summary>
        public FrameStats GetFrameStats()
        {
            IntPtr h = Live;
            FrameStats s = default;
            s.StructSize = (uint)sizeof(FrameStats);
            DrapeException.Check(Native.drape_context_get_frame_stats(h, &s));
            return s;
        }
    }
}
