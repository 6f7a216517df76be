// P/Invoke declarations for EVERY function of the C ABI in native/include/drape/drape.h, in the
// header's order and with the header's names. Drape.Tests checks that the two lists agree
// (NativeApiTests), so a function added to the header without a line here fails CI.
//
// Only blittable types cross: pointers, IntPtr/UIntPtr, int/uint/float/double, int-backed enums and the
// blittable structs of Types.cs. Nothing is marshalled (no bool, no string, no array): strings
// coming back are `const char*` (IntPtr, decoded by Utf8.FromNative), strings going in are
// NUL-terminated UTF-8 byte buffers (Utf8.ToNative). Handles are opaque IntPtr.
using System;
using System.Runtime.InteropServices;

namespace Drape
{
    internal static unsafe class Native
    {
        /// <summary>
        /// The one place the native library's name is written. "drape" resolves to libdrape.so
        /// (Linux, Android), libdrape.dylib (macOS) and drape.dll (Windows). On iOS (and WebGL)
        /// the library is linked statically into the player, and P/Invoke must name "__Internal"
        /// instead: Unity defines UNITY_IOS when it compiles these sources for an iOS player.
        /// A prebuilt Drape.dll (compiled outside Unity) always says "drape".
        /// </summary>
        internal const string LibraryName =
#if (UNITY_IOS || UNITY_WEBGL) && !UNITY_EDITOR
            "__Internal";
#else
            "drape";
#endif

        /// <summary>The header version these declarations were written against (DRAPE_VERSION_*).
        /// Only the major part must match the loaded library (see DrapeLibrary.EnsureCompatible).</summary>
        internal const uint HeaderVersionMajor = 0;
        internal const uint HeaderVersionMinor = 2;
        internal const uint HeaderVersionPatch = 0;

        private const CallingConvention Cdecl = CallingConvention.Cdecl;

        // ---- Results and errors ----------------------------------------------------------------

        [DllImport(LibraryName, CallingConvention = Cdecl, ExactSpelling = true)]
        internal static extern IntPtr drape_result_name(ResultCode result);

        [DllImport(LibraryName, CallingConvention = Cdecl, ExactSpelling = true)]
        internal static extern IntPtr drape_last_error();

        // ---- Version ---------------------------------------------------------------------------

        [DllImport(LibraryName, CallingConvention = Cdecl, ExactSpelling = true)]
        internal static extern uint drape_version();

        [DllImport(LibraryName, CallingConvention = Cdecl, ExactSpelling = true)]
        internal static extern IntPtr drape_version_string();

        // ---- Context ---------------------------------------------------------------------------

        /// <summary>The sized init, which <see cref="ContextDesc.CreateDefault"/> calls with the
        /// struct's own size.</summary>
        [DllImport(LibraryName, CallingConvention = Cdecl, ExactSpelling = true)]
        internal static extern ResultCode drape_context_desc_init_sized(ContextDesc* desc, uint structSize);

        /// <summary>The exported init of the struct's 72-byte layout, for hosts built before the
        /// sized init. Declared because every drape.h function is; not called.</summary>
        [DllImport(LibraryName, CallingConvention = Cdecl, ExactSpelling = true)]
        internal static extern ResultCode drape_context_desc_init(ContextDesc* desc);

        [DllImport(LibraryName, CallingConvention = Cdecl, ExactSpelling = true)]
        internal static extern ResultCode drape_context_create(ContextDesc* desc, IntPtr* outContext);

        [DllImport(LibraryName, CallingConvention = Cdecl, ExactSpelling = true)]
        internal static extern ResultCode drape_context_destroy(IntPtr context);

        // ---- Body shape ------------------------------------------------------------------------

        [DllImport(LibraryName, CallingConvention = Cdecl, ExactSpelling = true)]
        internal static extern ResultCode drape_body_shape_init(BodyShape* shape);

        [DllImport(LibraryName, CallingConvention = Cdecl, ExactSpelling = true)]
        internal static extern ResultCode drape_context_set_body_shape(IntPtr context, BodyShape* shape);

        [DllImport(LibraryName, CallingConvention = Cdecl, ExactSpelling = true)]
        internal static extern ResultCode drape_context_get_body_shape(IntPtr context, BodyShape* outShape);

        // ---- Skeleton input --------------------------------------------------------------------

        [DllImport(LibraryName, CallingConvention = Cdecl, ExactSpelling = true)]
        internal static extern ResultCode drape_context_push_skeleton(IntPtr context, SkeletonFrame* frame);

        [DllImport(LibraryName, CallingConvention = Cdecl, ExactSpelling = true)]
        internal static extern ResultCode drape_context_update(IntPtr context);

        [DllImport(LibraryName, CallingConvention = Cdecl, ExactSpelling = true)]
        internal static extern ResultCode drape_context_read_skeleton(IntPtr context, Vector3f* positions,
                                                                      uint capacity, uint* outCount);

        // ---- Body mesh -------------------------------------------------------------------------

        [DllImport(LibraryName, CallingConvention = Cdecl, ExactSpelling = true)]
        internal static extern ResultCode drape_context_get_body_mesh_size(IntPtr context, uint* outVertexCount,
                                                                           uint* outIndexCount);

        [DllImport(LibraryName, CallingConvention = Cdecl, ExactSpelling = true)]
        internal static extern ResultCode drape_context_read_body_mesh(IntPtr context, Vector3f* positions,
                                                                       Vector3f* normals, uint vertexCapacity,
                                                                       uint* indices, uint indexCapacity);

        // ---- Statistics ------------------------------------------------------------------------

        [DllImport(LibraryName, CallingConvention = Cdecl, ExactSpelling = true)]
        internal static extern ResultCode drape_context_get_ellipsoid_count(IntPtr context, uint* outCount);

        [DllImport(LibraryName, CallingConvention = Cdecl, ExactSpelling = true)]
        internal static extern ResultCode drape_context_read_ellipsoids(IntPtr context, Ellipsoid* ellipsoids,
            uint capacity, uint* outCount);

        [DllImport(LibraryName, CallingConvention = Cdecl, ExactSpelling = true)]
        internal static extern ResultCode drape_context_read_ellipsoid_matrices(IntPtr context, float* matrices,
            uint capacity, uint* outCount);

        [DllImport(LibraryName, CallingConvention = Cdecl, ExactSpelling = true)]
        internal static extern ResultCode drape_context_measure_proxy_fidelity(IntPtr context, ProxyFidelity* outFidelity);

        [DllImport(LibraryName, CallingConvention = Cdecl, ExactSpelling = true)]
        internal static extern ResultCode drape_context_get_frame_stats(IntPtr context, FrameStats* outStats);

        // ---- Garments --------------------------------------------------------------------------

        [DllImport(LibraryName, CallingConvention = Cdecl, ExactSpelling = true)]
        internal static extern ResultCode drape_garment_desc_init(GarmentDesc* desc);

        [DllImport(LibraryName, CallingConvention = Cdecl, ExactSpelling = true)]
        internal static extern ResultCode drape_garment_template_init(GarmentTemplate* tmpl);

        /// <summary>The sized init, which <see cref="ClothParams.CreateDefault"/> calls with the
        /// struct's own size.</summary>
        [DllImport(LibraryName, CallingConvention = Cdecl, ExactSpelling = true)]
        internal static extern ResultCode drape_cloth_params_init_sized(ClothParams* parameters, uint structSize);

        /// <summary>The exported first-layout init: fills 128 bytes (struct_size 128), for hosts built
        /// before collision_stride. Declared because every drape.h function is; not called.</summary>
        [DllImport(LibraryName, CallingConvention = Cdecl, ExactSpelling = true)]
        internal static extern ResultCode drape_cloth_params_init(ClothParams* parameters);

        /// <param name="context">drape_context*.</param>
        /// <param name="desc">optional (NULL: defaults).</param>
        /// <param name="tmpl">optional (NULL: the default T-shirt).</param>
        /// <param name="cloth">optional (NULL: defaults).</param>
        /// <param name="outGarment">receives the new drape_garment*, owned by the context.</param>
        [DllImport(LibraryName, CallingConvention = Cdecl, ExactSpelling = true)]
        internal static extern ResultCode drape_context_add_garment_template(IntPtr context, GarmentDesc* desc,
            GarmentTemplate* tmpl, ClothParams* cloth, IntPtr* outGarment);

        [DllImport(LibraryName, CallingConvention = Cdecl, ExactSpelling = true)]
        internal static extern ResultCode drape_mesh_fit_init(MeshFit* fit);

        /// <param name="context">drape_context*.</param>
        /// <param name="pathUtf8">NUL-terminated UTF-8 path (see Utf8.ToNative).</param>
        /// <param name="fit">optional (NULL: defaults).</param>
        /// <param name="desc">optional (NULL: defaults).</param>
        /// <param name="cloth">optional (NULL: defaults).</param>
        /// <param name="outGarment">receives the new drape_garment*, owned by the context.</param>
        [DllImport(LibraryName, CallingConvention = Cdecl, ExactSpelling = true)]
        internal static extern ResultCode drape_context_add_garment_obj_file(IntPtr context, byte* pathUtf8,
            MeshFit* fit, GarmentDesc* desc, ClothParams* cloth, IntPtr* outGarment);

        /// <param name="context">drape_context*.</param>
        /// <param name="data">OBJ text (copied by the library).</param>
        /// <param name="size">size_t byte count.</param>
        /// <param name="fit">optional (NULL: defaults).</param>
        /// <param name="desc">optional (NULL: defaults).</param>
        /// <param name="cloth">optional (NULL: defaults).</param>
        /// <param name="outGarment">receives the new drape_garment*, owned by the context.</param>
        [DllImport(LibraryName, CallingConvention = Cdecl, ExactSpelling = true)]
        internal static extern ResultCode drape_context_add_garment_obj_memory(IntPtr context, void* data, UIntPtr size,
            MeshFit* fit, GarmentDesc* desc, ClothParams* cloth, IntPtr* outGarment);

        [DllImport(LibraryName, CallingConvention = Cdecl, ExactSpelling = true)]
        internal static extern ResultCode drape_context_add_garment_mesh(IntPtr context, Vector3f* positions,
            uint vertexCount, uint* indices, uint indexCount, MeshFit* fit, GarmentDesc* desc, ClothParams* cloth,
            IntPtr* outGarment);

        [DllImport(LibraryName, CallingConvention = Cdecl, ExactSpelling = true)]
        internal static extern ResultCode drape_garment_destroy(IntPtr garment);

        [DllImport(LibraryName, CallingConvention = Cdecl, ExactSpelling = true)]
        internal static extern ResultCode drape_garment_set_params(IntPtr garment, ClothParams* parameters);

        [DllImport(LibraryName, CallingConvention = Cdecl, ExactSpelling = true)]
        internal static extern ResultCode drape_garment_get_params(IntPtr garment, ClothParams* outParams);

        [DllImport(LibraryName, CallingConvention = Cdecl, ExactSpelling = true)]
        internal static extern ResultCode drape_garment_set_layer(IntPtr garment, int layer);

        [DllImport(LibraryName, CallingConvention = Cdecl, ExactSpelling = true)]
        internal static extern ResultCode drape_garment_get_layer(IntPtr garment, int* outLayer);

        [DllImport(LibraryName, CallingConvention = Cdecl, ExactSpelling = true)]
        internal static extern ResultCode drape_context_step(IntPtr context, float dt);

        [DllImport(LibraryName, CallingConvention = Cdecl, ExactSpelling = true)]
        internal static extern ResultCode drape_garment_get_mesh_size(IntPtr garment, uint* outVertexCount,
                                                                      uint* outIndexCount);

        [DllImport(LibraryName, CallingConvention = Cdecl, ExactSpelling = true)]
        internal static extern ResultCode drape_garment_read_mesh(IntPtr garment, Vector3f* positions, Vector3f* normals,
                                                                  uint vertexCapacity, uint* indices, uint indexCapacity);

        [DllImport(LibraryName, CallingConvention = Cdecl, ExactSpelling = true)]
        internal static extern ResultCode drape_garment_read_rest_positions(IntPtr garment, Vector3f* positions,
                                                                            uint vertexCapacity);

        /// <param name="garment">drape_garment*.</param>
        /// <param name="outXyzw">receives a library-owned pointer to vertex_count float4 (x, y, z, inverse mass).</param>
        /// <param name="outVertexCount">optional.</param>
        [DllImport(LibraryName, CallingConvention = Cdecl, ExactSpelling = true)]
        internal static extern ResultCode drape_garment_view_positions(IntPtr garment, float** outXyzw,
                                                                       uint* outVertexCount);

        [DllImport(LibraryName, CallingConvention = Cdecl, ExactSpelling = true)]
        internal static extern ResultCode drape_garment_get_stats(IntPtr garment, GarmentStats* outStats);

        [DllImport(LibraryName, CallingConvention = Cdecl, ExactSpelling = true)]
        internal static extern ResultCode drape_garment_measure(IntPtr garment, GarmentAccuracy* outAccuracy);

        // ---- Adaptive pipeline (Pipeline.cs) ---------------------------------------------------

        [DllImport(LibraryName, CallingConvention = Cdecl, ExactSpelling = true)]
        internal static extern ResultCode drape_pipeline_options_init(PipelineOptions* options);

        [DllImport(LibraryName, CallingConvention = Cdecl, ExactSpelling = true)]
        internal static extern ResultCode drape_context_set_pipeline_options(IntPtr context, PipelineOptions* options);

        [DllImport(LibraryName, CallingConvention = Cdecl, ExactSpelling = true)]
        internal static extern ResultCode drape_context_get_pipeline_options(IntPtr context, PipelineOptions* outOptions);

        [DllImport(LibraryName, CallingConvention = Cdecl, ExactSpelling = true)]
        internal static extern ResultCode drape_context_wake(IntPtr context);

        [DllImport(LibraryName, CallingConvention = Cdecl, ExactSpelling = true)]
        internal static extern ResultCode drape_context_get_skip_stats(IntPtr context, SkipStats* outStats);

        // ---- Recordings ------------------------------------------------------------------------

        /// <param name="pathUtf8">NUL-terminated UTF-8 path (see Utf8.ToNative).</param>
        /// <param name="layout">drape_layout as int32_t.</param>
        /// <param name="outRecording">receives the new handle.</param>
        [DllImport(LibraryName, CallingConvention = Cdecl, ExactSpelling = true)]
        internal static extern ResultCode drape_recording_open(byte* pathUtf8, int layout, IntPtr* outRecording);

        /// <param name="data">the bytes (copied by the library).</param>
        /// <param name="size">size_t byte count.</param>
        /// <param name="layout">drape_layout as int32_t.</param>
        /// <param name="outRecording">receives the new handle.</param>
        [DllImport(LibraryName, CallingConvention = Cdecl, ExactSpelling = true)]
        internal static extern ResultCode drape_recording_open_memory(void* data, UIntPtr size, int layout,
                                                                      IntPtr* outRecording);

        [DllImport(LibraryName, CallingConvention = Cdecl, ExactSpelling = true)]
        internal static extern ResultCode drape_recording_destroy(IntPtr recording);

        [DllImport(LibraryName, CallingConvention = Cdecl, ExactSpelling = true)]
        internal static extern ResultCode drape_recording_get_info(IntPtr recording, RecordingInfo* outInfo);

        [DllImport(LibraryName, CallingConvention = Cdecl, ExactSpelling = true)]
        internal static extern ResultCode drape_recording_read_frame(IntPtr recording, uint index, Joint* joints,
                                                                     uint capacity, double* outTimestampS);

        [DllImport(LibraryName, CallingConvention = Cdecl, ExactSpelling = true)]
        internal static extern ResultCode drape_recording_save(IntPtr recording, byte* pathUtf8);

        // ---- Backends --------------------------------------------------------------------------

        [DllImport(LibraryName, CallingConvention = Cdecl, ExactSpelling = true)]
        internal static extern ResultCode drape_backend_desc_init(BackendDesc* desc);

        [DllImport(LibraryName, CallingConvention = Cdecl, ExactSpelling = true)]
        internal static extern ResultCode drape_context_set_backend(IntPtr context, BackendDesc* desc);

        [DllImport(LibraryName, CallingConvention = Cdecl, ExactSpelling = true)]
        internal static extern ResultCode drape_context_get_backend_info(IntPtr context, BackendInfo* outInfo);

        [DllImport(LibraryName, CallingConvention = Cdecl, ExactSpelling = true)]
        internal static extern ResultCode drape_opencl_device_count(uint* outCount);

        [DllImport(LibraryName, CallingConvention = Cdecl, ExactSpelling = true)]
        internal static extern ResultCode drape_opencl_device_get(uint index, OpenClDeviceInfo* outDevice);

        [DllImport(LibraryName, CallingConvention = Cdecl, ExactSpelling = true)]
        internal static extern ResultCode drape_step_contexts(IntPtr* contexts, uint count, float dt);
    }

    /// <summary>UTF-8 conversions for the C ABI's <c>const char*</c>, without any marshaller.</summary>
    internal static unsafe class Utf8
    {
        /// <summary>Decodes a NUL-terminated UTF-8 string owned by the library ("" for NULL).</summary>
        internal static string FromNative(IntPtr text)
        {
            if (text == IntPtr.Zero) return string.Empty;
            byte* p = (byte*)text;
            int length = 0;
            while (p[length] != 0) ++length;
            return System.Text.Encoding.UTF8.GetString(p, length);
        }

        /// <summary>Encodes <paramref name="text"/> as NUL-terminated UTF-8 (the library's paths).</summary>
        internal static byte[] ToNative(string text, string paramName)
        {
            if (text is null) throw new ArgumentNullException(paramName);
            if (text.IndexOf('\0') >= 0) throw new ArgumentException("the string contains a NUL character", paramName);
            int n = System.Text.Encoding.UTF8.GetByteCount(text);
            var bytes = new byte[n + 1];
            System.Text.Encoding.UTF8.GetBytes(text, 0, text.Length, bytes, 0);
            return bytes;
        }
    }
}
