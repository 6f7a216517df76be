using System;
using System.Collections.Generic;
using System.Runtime.InteropServices;

namespace Drape
{
    /// <summary>
    /// One tracked person (drape_context): skeleton in, body mesh and garments out.
    /// <para>Owns its native handle: call <see cref="Dispose"/> (or use <c>using</c>). Not
    /// thread-safe: one thread at a time, Dispose included (the C ABI's rule). Different
    /// contexts may be used on different threads at once.</para>
    /// <para>A context that is garbage-collected without Dispose is leaked, not freed: its
    /// finalizer calls no native code and only reports the leak
    /// (<see cref="DrapeLibrary.LeakedHandleCount"/>, <see cref="DrapeLibrary.HandleLeaked"/>).</para>
    /// <para>The context owns its <see cref="Garment"/>s: disposing it destroys them and makes
    /// every later call on them throw <see cref="ObjectDisposedException"/>.</para>
    /// </summary>
    public sealed unsafe partial class Context : IDisposable
    {
        private IntPtr _handle;
        private readonly List<Garment> _garments;
        private readonly System.Collections.ObjectModel.ReadOnlyCollection<Garment> _garmentsView;

        /// <summary>Creates a context with the default settings.</summary>
        public Context()
        {
            _garments = new List<Garment>();
            _garmentsView = _garments.AsReadOnly();
            DrapeLibrary.EnsureCompatible();
            IntPtr h;
            DrapeException.Check(Native.drape_context_create(null, &h));
            _handle = h;
        }

        /// <summary>Creates a context with <paramref name="desc"/>; start it from
        /// <see cref="ContextDesc.CreateDefault"/> (a zero StructSize is rejected).</summary>
        public Context(in ContextDesc desc)
        {
            _garments = new List<Garment>();
            _garmentsView = _garments.AsReadOnly();
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

        /// <summary>Destroys the native context (drape_context_destroy) and with it every garment
        /// it still owns (their objects become disposed). Idempotent.</summary>
        public void Dispose()
        {
            IntPtr h = _handle;
            if (h == IntPtr.Zero) return;
            _handle = IntPtr.Zero;
            GC.SuppressFinalize(this);
            foreach (Garment g in _garments) g.Orphan();
            _garments.Clear();
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
        /// <see cref="BodyShape.CreateDefault"/>. Garments already added are refitted to the new
        /// body: same vertices and triangles, cut carried to the new body and dressed there (tens of
        /// milliseconds per garment); the same measurements again change nothing. On failure the
        /// previous shape and garments are kept.</summary>
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
            // ReadOnlySpan is pinned through MemoryMarshal.GetReference, not `fixed (T* p = span)`:
            // see Pinning.cs (Mono 6's corlib lacks the signature `fixed` compiles to).
            fixed (Joint* pj0 = &MemoryMarshal.GetReference(joints))
            fixed (Quaternionf* pq0 = &MemoryMarshal.GetReference(orientations))
            {
                Joint* pj = Pinning.OrNull(pj0, joints.Length);
                Quaternionf* pq = Pinning.OrNull(pq0, orientations.Length);
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

        // ---- Garments ----------------------------------------------------------------------------

        /// <summary>The garments this context owns now, in the order they were added (disposed ones
        /// are removed).</summary>
        public IReadOnlyList<Garment> Garments => _garmentsView;

        internal void Forget(Garment garment) => _garments.Remove(garment);

        private Garment Adopt(IntPtr garmentHandle)
        {
            var g = new Garment(this, garmentHandle);
            _garments.Add(g);
            return g;
        }

        /// <summary>
        /// Adds a procedural garment sized to the body shape and dressed on the body's rest pose
        /// (drape_context_add_garment_template; about a millisecond per 1 000 particles, plus the
        /// settling of <see cref="GarmentDesc.DressTimeS"/>). Start <paramref name="template"/> from
        /// <see cref="GarmentTemplate.CreateDefault(GarmentKind)"/>; <paramref name="desc"/> and
        /// <paramref name="cloth"/> default to the library's defaults when null.
        /// </summary>
        public Garment AddGarment(in GarmentTemplate template, GarmentDesc? desc = null, ClothParams? cloth = null)
        {
            IntPtr h = Live;
            GarmentTemplate t = template;
            GarmentDesc d = desc.GetValueOrDefault();
            ClothParams c = cloth.GetValueOrDefault();
            IntPtr g;
            DrapeException.Check(Native.drape_context_add_garment_template(
                h, desc.HasValue ? &d : null, &t, cloth.HasValue ? &c : null, &g));
            return Adopt(g);
        }

        /// <summary>
        /// Adds a garment from a Wavefront OBJ file (drape_context_add_garment_obj_file; the path is
        /// passed as UTF-8): faces of 3+ vertices, retargeted onto this body by
        /// <paramref name="fit"/> (null: MakeHuman's defaults, see docs/garment-obj.md) and attached
        /// at its top boundary loop (waistband, collar) when one winds around the torso. Throws
        /// <see cref="ResultCode.Io"/> when the file cannot be read and <see cref="ResultCode.Parse"/>
        /// when it is not OBJ.
        /// </summary>
        public Garment AddGarmentObj(string path, MeshFit? fit = null, GarmentDesc? desc = null, ClothParams? cloth = null)
        {
            IntPtr h = Live;
            byte[] utf8 = Utf8.ToNative(path, nameof(path));
            MeshFit f = fit.GetValueOrDefault();
            GarmentDesc d = desc.GetValueOrDefault();
            ClothParams c = cloth.GetValueOrDefault();
            IntPtr g;
            fixed (byte* p = utf8)
                DrapeException.Check(Native.drape_context_add_garment_obj_file(
                    h, p, fit.HasValue ? &f : null, desc.HasValue ? &d : null, cloth.HasValue ? &c : null, &g));
            return Adopt(g);
        }

        /// <summary>As <see cref="AddGarmentObj"/>, from OBJ text in memory
        /// (drape_context_add_garment_obj_memory; the bytes are copied). A byte[] converts implicitly.</summary>
        public Garment AddGarmentObjMemory(ReadOnlySpan<byte> objText, MeshFit? fit = null, GarmentDesc? desc = null,
                                           ClothParams? cloth = null)
        {
            IntPtr h = Live;
            MeshFit f = fit.GetValueOrDefault();
            GarmentDesc d = desc.GetValueOrDefault();
            ClothParams c = cloth.GetValueOrDefault();
            IntPtr g;
            byte none = 0;  // an empty span is empty text (a Parse error), not a NULL pointer
            fixed (byte* p0 = &MemoryMarshal.GetReference(objText))
            {
                byte* p = Pinning.OrNull(p0, objText.Length);
                DrapeException.Check(Native.drape_context_add_garment_obj_memory(
                    h, p != null ? p : &none, (UIntPtr)(uint)objText.Length, fit.HasValue ? &f : null,
                    desc.HasValue ? &d : null, cloth.HasValue ? &c : null, &g));
            }
            return Adopt(g);
        }

        /// <summary>
        /// Adds a garment from a triangle mesh (drape_context_add_garment_mesh; copied):
        /// <paramref name="positions"/> in the mesh's own units (placed as <paramref name="fit"/>
        /// says, as for OBJ files), <paramref name="indices"/> a multiple of 3, counter-clockwise
        /// seen from outside. A <c>UnityEngine.Vector3</c> span can be passed with
        /// <c>MemoryMarshal.Cast&lt;Vector3, Vector3f&gt;</c>.
        /// </summary>
        public Garment AddGarmentMesh(ReadOnlySpan<Vector3f> positions, ReadOnlySpan<uint> indices, MeshFit? fit = null,
                                      GarmentDesc? desc = null, ClothParams? cloth = null)
        {
            IntPtr h = Live;
            MeshFit f = fit.GetValueOrDefault();
            GarmentDesc d = desc.GetValueOrDefault();
            ClothParams c = cloth.GetValueOrDefault();
            IntPtr g;
            Vector3f noVertex;
            uint noIndex;
            fixed (Vector3f* pp0 = &MemoryMarshal.GetReference(positions))
            fixed (uint* pi0 = &MemoryMarshal.GetReference(indices))
            {
                Vector3f* pp = Pinning.OrNull(pp0, positions.Length);
                uint* pi = Pinning.OrNull(pi0, indices.Length);
                DrapeException.Check(Native.drape_context_add_garment_mesh(
                    h, pp != null ? pp : &noVertex, (uint)positions.Length, pi != null ? pi : &noIndex,
                    (uint)indices.Length, fit.HasValue ? &f : null, desc.HasValue ? &d : null,
                    cloth.HasValue ? &c : null, &g));
            }
            return Adopt(g);
        }

        /// <summary>
        /// Advances the world by <paramref name="dt"/> seconds, the host's frame time, in (0, 10]
        /// (drape_context_step): runs <see cref="Update"/> if a frame is queued, then every garment
        /// follows the body from where it was at the last step, in ceil(dt * SubstepHz) substeps
        /// (the cloth simulates dt clamped to [1e-5 s, MaxStepS]).
        /// Throws <see cref="ResultCode.CallOrder"/> before the first accepted frame. Invalidates
        /// every <see cref="Garment.ViewPositions"/> span. No managed allocation.
        /// </summary>
        public void Step(float dt)
        {
            IntPtr h = Live;
            DrapeException.Check(Native.drape_context_step(h, dt));
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
