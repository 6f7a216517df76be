using System;

namespace Drape
{
    /// <summary>
    /// A garment worn by a <see cref="Context"/>'s person (drape_garment): a cloth simulated against
    /// the tracking ellipsoids and attached to the body's rings. Created by
    /// <see cref="Context.AddGarment(in GarmentTemplate, GarmentDesc?, ClothParams?)"/>,
    /// <see cref="Context.AddGarmentObj"/>, <see cref="Context.AddGarmentObjMemory"/> or
    /// <see cref="Context.AddGarmentMesh"/>; advanced by <see cref="Context.Step"/>.
    /// <para><b>Owned by its context.</b> <see cref="Dispose"/> removes the garment early
    /// (drape_garment_destroy); disposing the context destroys all its garments, and from then on
    /// every member of this object throws <see cref="ObjectDisposedException"/> (no native call is
    /// made with the dead handle). The context keeps a reference to each of its live garments, so a
    /// garment is never garbage-collected before its context and needs no finalizer: a leaked
    /// context (reported by its own finalizer) leaks its garments with it.</para>
    /// <para>Threading: the context's rule. One thread at a time per context, and that includes
    /// every call on its garments.</para>
    /// </summary>
    public sealed unsafe class Garment : IDisposable
    {
        private IntPtr _handle;
        private readonly Context _context;

        internal Garment(Context context, IntPtr handle)
        {
            _context = context;
            _handle = handle;
            uint vertices = 0, indices = 0;
            ResultCode r = Native.drape_garment_get_mesh_size(handle, &vertices, &indices);
            if (r != ResultCode.Ok)
            {
                DrapeException e = DrapeException.FromLastError(r);
                Native.drape_garment_destroy(handle);
                _handle = IntPtr.Zero;
                throw e;
            }
            VertexCount = (int)vertices;
            IndexCount = (int)indices;
        }

        /// <summary>The context that owns the garment.</summary>
        public Context Context => _context;

        /// <summary>The native drape_garment* (for interop with other native code), or
        /// <see cref="IntPtr.Zero"/> once the garment or its context is disposed.</summary>
        public IntPtr Handle => _handle;

        /// <summary>True once <see cref="Dispose"/> has run or the owning context was disposed.</summary>
        public bool IsDisposed => _handle == IntPtr.Zero;

        /// <summary>Particles (mesh vertices); fixed for the garment. Still readable after Dispose.</summary>
        public int VertexCount { get; }

        /// <summary>Triangle indices (3 per triangle); fixed for the garment. Still readable after Dispose.</summary>
        public int IndexCount { get; }

        /// <summary>Removes the garment from its context and frees it (drape_garment_destroy).
        /// Idempotent; does nothing once the context is disposed (the context freed it).</summary>
        public void Dispose()
        {
            IntPtr h = _handle;
            if (h == IntPtr.Zero) return;
            _handle = IntPtr.Zero;
            _context.Forget(this);
            // Cannot fail for a live handle of a live context; nothing useful to do if it did.
            Native.drape_garment_destroy(h);
        }

        /// <summary>Called by the owning context when it is disposed: the native side has freed the
        /// garment and invalidated its handle.</summary>
        internal void Orphan() => _handle = IntPtr.Zero;

        private IntPtr Live
        {
            get
            {
                IntPtr h = _handle;
                if (h == IntPtr.Zero)
                    throw new ObjectDisposedException(nameof(Garment),
                        _context.IsDisposed ? "The garment's Context was disposed, which destroyed the garment."
                                            : "The garment was disposed.");
                return h;
            }
        }

        // ---- Parameters --------------------------------------------------------------------------

        /// <summary>The cloth parameters (drape_garment_get_params / drape_garment_set_params). Set
        /// replaces them as a whole, validated as a whole: on failure it throws
        /// <see cref="DrapeException"/> (<see cref="ResultCode.NonFinite"/>,
        /// <see cref="ResultCode.OutOfRange"/>, ...) and the garment keeps its parameters. Start
        /// from the current value or <see cref="ClothParams.CreateDefault"/> (a zero StructSize is
        /// rejected). Setting invalidates <see cref="ViewPositions"/> spans.</summary>
        public ClothParams Params
        {
            get
            {
                IntPtr h = Live;
                ClothParams p = default;
                p.StructSize = (uint)sizeof(ClothParams);
                DrapeException.Check(Native.drape_garment_get_params(h, &p));
                return p;
            }
            set => SetParams(value);
        }

        /// <summary>As setting <see cref="Params"/>, without copying the struct twice.</summary>
        public void SetParams(in ClothParams parameters)
        {
            IntPtr h = Live;
            ClothParams p = parameters;
            DrapeException.Check(Native.drape_garment_set_params(h, &p));
        }

        /// <summary>The garment's layer (drape_garment_set_layer / drape_garment_get_layer): a garment
        /// of layer L &gt;= 2 is worn over every garment of its context whose layer is 1 .. L - 1 (a
        /// T-shirt over trousers: trousers 1, T-shirt 2) and lies on their cloth instead of passing
        /// through it; 0, the default, is not layered. In [0, 255]: outside it throws
        /// <see cref="DrapeException"/> (<see cref="ResultCode.OutOfRange"/>) and nothing changes.
        /// docs/garments.md, "Layered garments".</summary>
        public int Layer
        {
            get
            {
                IntPtr h = Live;
                int layer;
                DrapeException.Check(Native.drape_garment_get_layer(h, &layer));
                return layer;
            }
            set => DrapeException.Check(Native.drape_garment_set_layer(Live, value));
        }

        // ---- Mesh --------------------------------------------------------------------------------

        /// <summary>
        /// Copies the current garment mesh (drape_garment_read_mesh). An empty span skips that array;
        /// at least one must be non-empty. A non-empty span shorter than <see cref="VertexCount"/>
        /// (positions, normals) or <see cref="IndexCount"/> (indices) throws
        /// <see cref="ResultCode.BufferTooSmall"/> and nothing is written. Normals are computed on
        /// request (area-weighted, unit); indices are counter-clockwise seen from outside.
        /// </summary>
        public void ReadMesh(Span<Vector3f> positions, Span<Vector3f> normals, Span<uint> indices)
        {
            IntPtr h = Live;
            int vertexCapacity = positions.IsEmpty ? normals.Length
                : normals.IsEmpty ? positions.Length
                : Math.Min(positions.Length, normals.Length);
            fixed (Vector3f* pp = positions)
            fixed (Vector3f* pn = normals)
            fixed (uint* pi = indices)
            {
                DrapeException.Check(Native.drape_garment_read_mesh(
                    h, pp, pn, (uint)vertexCapacity, pi, (uint)indices.Length));
            }
        }

        /// <summary>Copies the particle positions (metres, camera space) into
        /// <paramref name="positions"/>, at least <see cref="VertexCount"/> long (else
        /// <see cref="ResultCode.BufferTooSmall"/>, nothing written). No managed allocation.</summary>
        public void ReadPositions(Span<Vector3f> positions)
        {
            IntPtr h = Live;
            Vector3f none;  // an empty span still names a buffer (of capacity 0): BufferTooSmall, not NullArgument
            fixed (Vector3f* p = positions)
                DrapeException.Check(Native.drape_garment_read_mesh(
                    h, p != null ? p : &none, null, (uint)positions.Length, null, 0));
        }

        /// <summary>Copies the garment's rest shape (every edge at its rest length; fixed for the
        /// garment) into <paramref name="positions"/>, at least <see cref="VertexCount"/> long.</summary>
        public void ReadRestPositions(Span<Vector3f> positions)
        {
            IntPtr h = Live;
            Vector3f none;
            fixed (Vector3f* p = positions)
                DrapeException.Check(Native.drape_garment_read_rest_positions(h, p != null ? p : &none, (uint)positions.Length));
        }

        /// <summary>Computes and copies unit vertex normals (area-weighted) into
        /// <paramref name="normals"/>, at least <see cref="VertexCount"/> long.</summary>
        public void ReadNormals(Span<Vector3f> normals)
        {
            IntPtr h = Live;
            Vector3f none;
            fixed (Vector3f* p = normals)
                DrapeException.Check(Native.drape_garment_read_mesh(
                    h, null, p != null ? p : &none, (uint)normals.Length, null, 0));
        }

        /// <summary>Copies the triangle indices (counter-clockwise seen from outside, 3 per triangle;
        /// fixed for the garment) into <paramref name="indices"/>, at least <see cref="IndexCount"/> long.</summary>
        public void ReadIndices(Span<uint> indices)
        {
            IntPtr h = Live;
            uint none;
            fixed (uint* p = indices)
                DrapeException.Check(Native.drape_garment_read_mesh(
                    h, null, null, 0, p != null ? p : &none, (uint)indices.Length));
        }

        /// <summary>
        /// A borrowed, zero-copy view of the particles (drape_garment_view_positions):
        /// <see cref="VertexCount"/> float4 = 4 * VertexCount floats, (x, y, z) in metres and w the
        /// inverse mass (0 for particles attached to the body).
        /// <para><b>The span points into the library's memory and is valid only until the next
        /// <see cref="Context.Step"/>, <see cref="Context.SetBodyShape"/>, <see cref="Params"/> set, <see cref="Dispose"/> or
        /// <see cref="Drape.Context.Dispose"/>.</b> Reading it after any of these reads freed or
        /// stale memory (the runtime cannot detect it). Do not keep it across frames: call
        /// ViewPositions again after each Step. Read-only: writing through it (via unsafe casts) is
        /// undefined behaviour.</para>
        /// </summary>
        public ReadOnlySpan<float> ViewPositions()
        {
            IntPtr h = Live;
            float* p = null;
            uint n = 0;
            DrapeException.Check(Native.drape_garment_view_positions(h, &p, &n));
            return new ReadOnlySpan<float>(p, checked((int)n * 4));
        }

        // ---- Statistics --------------------------------------------------------------------------

        /// <summary>What the last step did (drape_garment_get_stats).</summary>
        public GarmentStats Stats
        {
            get
            {
                IntPtr h = Live;
                GarmentStats s = default;
                s.StructSize = (uint)sizeof(GarmentStats);
                DrapeException.Check(Native.drape_garment_get_stats(h, &s));
                return s;
            }
        }

        /// <summary>Measures the garment's accuracy now (drape_garment_measure; a diagnostic, about
        /// 0.6 ms per 1 000 particles, not a per-frame call).</summary>
        public GarmentAccuracy Measure()
        {
            IntPtr h = Live;
            GarmentAccuracy a = default;
            a.StructSize = (uint)sizeof(GarmentAccuracy);
            DrapeException.Check(Native.drape_garment_measure(h, &a));
            return a;
        }
    }
}
