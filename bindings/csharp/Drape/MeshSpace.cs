using System;
using System.Runtime.InteropServices;

namespace Drape
{
    /// <summary>How to take Drape's right-handed camera space into a host's space.</summary>
    public enum AxisFlip
    {
        /// <summary>As the library gives it: right-handed sensor camera space.</summary>
        None = 0,
        /// <summary>Negate x: left-handed, y up, z away from the sensor. A Unity camera at the
        /// origin looking along +Z then sees the person as the sensor did (not mirrored).</summary>
        X = 1,
        /// <summary>Negate z: left-handed, the person behind the origin facing +Z (mirror view
        /// for a camera at the origin looking along -Z).</summary>
        Z = 2,
    }

    /// <summary>
    /// Reads body and garment meshes straight into a host's arrays, converted to its handedness:
    /// positions and normals reflected by <see cref="AxisFlip"/>, triangle winding reversed with it
    /// (so faces stay front-facing and normals outward). Meant for Unity: pass a
    /// <c>Vector3[]</c> as <c>MemoryMarshal.Cast&lt;Vector3, Vector3f&gt;(array.AsSpan())</c> and an
    /// <c>int[]</c> of triangles as is. No managed allocation.
    /// </summary>
    public static class MeshSpace
    {
        /// <summary>Reflects <paramref name="vectors"/> in place (positions or normals).</summary>
        public static void Apply(Span<Vector3f> vectors, AxisFlip flip)
        {
            switch (flip)
            {
                case AxisFlip.None:
                    return;
                case AxisFlip.X:
                    for (int i = 0; i < vectors.Length; ++i) vectors[i].X = -vectors[i].X;
                    return;
                case AxisFlip.Z:
                    for (int i = 0; i < vectors.Length; ++i) vectors[i].Z = -vectors[i].Z;
                    return;
                default:
                    throw new ArgumentOutOfRangeException(nameof(flip), flip, "not an AxisFlip");
            }
        }

        // Only what the library wrote (the first `count`); an empty span was skipped.
        private static void ApplyPrefix(Span<Vector3f> vectors, int count, AxisFlip flip)
        {
            if (!vectors.IsEmpty) Apply(vectors.Slice(0, count), flip);
        }

        /// <summary>Reverses the winding of every triangle (swaps its 2nd and 3rd index) when
        /// <paramref name="flip"/> is a reflection. The length must be a multiple of 3.</summary>
        public static void ApplyWinding(Span<int> triangles, AxisFlip flip)
        {
            if (triangles.Length % 3 != 0)
                throw new ArgumentException($"{triangles.Length} indices is not a whole number of triangles", nameof(triangles));
            if (flip == AxisFlip.None) return;
            if (flip != AxisFlip.X && flip != AxisFlip.Z)
                throw new ArgumentOutOfRangeException(nameof(flip), flip, "not an AxisFlip");
            for (int t = 0; t < triangles.Length; t += 3)
            {
                int b = triangles[t + 1];
                triangles[t + 1] = triangles[t + 2];
                triangles[t + 2] = b;
            }
        }

        /// <summary>The garment's positions (and normals, unless empty) of the last step, converted.
        /// Spans at least <see cref="Garment.VertexCount"/> long.</summary>
        public static void ReadGarment(Garment garment, Span<Vector3f> positions, Span<Vector3f> normals, AxisFlip flip)
        {
            if (garment == null) throw new ArgumentNullException(nameof(garment));
            garment.ReadMesh(positions, normals, Span<uint>.Empty);
            ApplyPrefix(positions, garment.VertexCount, flip);
            ApplyPrefix(normals, garment.VertexCount, flip);
        }

        /// <summary>The garment's triangles (3 indices each, <see cref="Garment.IndexCount"/>; fixed
        /// for the garment: read once) with the winding for <paramref name="flip"/>.</summary>
        public static void ReadGarmentTriangles(Garment garment, Span<int> triangles, AxisFlip flip)
        {
            if (garment == null) throw new ArgumentNullException(nameof(garment));
            // Indices are below the vertex count, far below 2^31: the bits of a uint are the int's.
            garment.ReadIndices(MemoryMarshal.Cast<int, uint>(triangles));
            ApplyWinding(triangles.Slice(0, garment.IndexCount), flip);
        }

        /// <summary>The body's positions (and normals, unless empty) of the last update, converted.
        /// Spans at least <see cref="Context.GetBodyMeshSize"/>'s vertex count long.</summary>
        public static void ReadBody(Context context, Span<Vector3f> positions, Span<Vector3f> normals, AxisFlip flip)
        {
            if (context == null) throw new ArgumentNullException(nameof(context));
            context.ReadBodyMesh(positions, normals, Span<uint>.Empty);
            int count = context.GetBodyMeshSize().VertexCount;
            ApplyPrefix(positions, count, flip);
            ApplyPrefix(normals, count, flip);
        }

        /// <summary>The body's triangles (fixed for the context: read once), with the winding for
        /// <paramref name="flip"/>.</summary>
        public static void ReadBodyTriangles(Context context, Span<int> triangles, AxisFlip flip)
        {
            if (context == null) throw new ArgumentNullException(nameof(context));
            context.ReadBodyMesh(Span<Vector3f>.Empty, Span<Vector3f>.Empty, MemoryMarshal.Cast<int, uint>(triangles));
            ApplyWinding(triangles.Slice(0, context.GetBodyMeshSize().IndexCount), flip);
        }
    }
}
