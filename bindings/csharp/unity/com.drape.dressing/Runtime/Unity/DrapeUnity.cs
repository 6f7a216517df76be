// Unity-only glue for the Drape bindings (compiled by Unity with the package's Drape.asmdef; not by
// dotnet: Drape.UnityCheck compiles it against stand-ins of the UnityEngine types it uses).
using System;
using System.Runtime.InteropServices;
using UnityEngine;

namespace Drape
{
    /// <summary>Conversions between Unity's types and Drape's (same memory layout: no copies).</summary>
    public static class DrapeUnity
    {
        /// <summary>A <c>Vector3[]</c> seen as Drape vectors (Vector3 and Vector3f are both three
        /// floats): read meshes straight into a Mesh's vertex array.</summary>
        public static Span<Vector3f> AsDrape(this Vector3[] vectors) =>
            MemoryMarshal.Cast<Vector3, Vector3f>(vectors.AsSpan());

        /// <summary>Drape vectors seen as Unity's.</summary>
        public static Span<Vector3> AsUnity(this Vector3f[] vectors) =>
            MemoryMarshal.Cast<Vector3f, Vector3>(vectors.AsSpan());

        /// <summary>A mesh meant to be rewritten every frame: 32-bit indices, marked dynamic, with
        /// the given vertices (any values: they are rewritten every frame) and triangles.</summary>
        public static Mesh CreateDynamicMesh(string name, Vector3[] vertices, int[] triangles)
        {
            var mesh = new Mesh();
            mesh.name = name;
            mesh.indexFormat = UnityEngine.Rendering.IndexFormat.UInt32;
            mesh.MarkDynamic();
            mesh.SetVertices(vertices);
            mesh.SetTriangles(triangles, 0, false);
            return mesh;
        }

        /// <summary>Leaked Context/Recording objects (never disposed) are reported in the Console.</summary>
        [RuntimeInitializeOnLoadMethod]
        private static void ReportLeaks()
        {
            DrapeLibrary.HandleLeaked -= LogLeak;
            DrapeLibrary.HandleLeaked += LogLeak;
        }

        private static void LogLeak(string message) => Debug.LogWarning(message);
    }
}
