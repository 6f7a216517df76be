// The Backends section of drape.h (docs/opencl.md): where a context's garments run their cloth
// step, CPU or an OpenCL device. Structs mirror drape.h byte for byte (StructLayoutTests).
using System;
using System.Collections.Generic;
using System.Runtime.InteropServices;

namespace Drape
{
    /// <summary>drape_backend: where garments run their cloth step.</summary>
    public enum Backend : int
    {
        /// <summary>DRAPE_BACKEND_CPU: the default.</summary>
        Cpu = 0,
        /// <summary>DRAPE_BACKEND_OPENCL: every XPBD garment on the chosen OpenCL device.</summary>
        OpenCl = 1,
        /// <summary>DRAPE_BACKEND_AUTO: OpenCL for garments of at least OpenclMinParticles when a device works.</summary>
        Auto = 2,
    }

    /// <summary>drape_backend_desc: the backend choice; start from <see cref="CreateDefault"/>.</summary>
    [StructLayout(LayoutKind.Sequential)]
    public struct BackendDesc
    {
        /// <summary>struct_size: sizeof(drape_backend_desc).</summary>
        public uint StructSize;
        /// <summary>backend (<see cref="Drape.Backend"/>); default Cpu.</summary>
        public Backend Backend;
        /// <summary>platform_index: OpenCL platform, -1 = choose.</summary>
        public int PlatformIndex;
        /// <summary>device_index: device within the platform (or among all), -1 = choose.</summary>
        public int DeviceIndex;
        /// <summary>prefer_gpu: 1 = a GPU before other devices when choosing (default).</summary>
        public uint PreferGpu;
        /// <summary>opencl_min_particles: with Auto, smaller garments stay on the CPU (default 2000).</summary>
        public uint OpenclMinParticles;
        /// <summary>host_cl_context: optional cl_context of the host (with HostClQueue).</summary>
        public IntPtr HostClContext;
        /// <summary>host_cl_queue: optional cl_command_queue of the host (with HostClContext).</summary>
        public IntPtr HostClQueue;

        /// <summary>The library's defaults (drape_backend_desc_init).</summary>
        public static unsafe BackendDesc CreateDefault()
        {
            BackendDesc d;
            DrapeException.Check(Native.drape_backend_desc_init(&d));
            return d;
        }
    }

    /// <summary>drape_backend_info: the backend in use, as returned (strings are raw pointers valid
    /// until the next query; <see cref="Context.GetBackendInfo"/> copies them into <see cref="BackendStatus"/>).</summary>
    [StructLayout(LayoutKind.Sequential)]
    public struct BackendInfo
    {
        /// <summary>struct_size.</summary>
        public uint StructSize;
        /// <summary>requested: the backend last asked for.</summary>
        public Backend Requested;
        /// <summary>active: OpenCl when a device is in use, else Cpu.</summary>
        public Backend Active;
        /// <summary>opencl_garments.</summary>
        public uint OpenclGarments;
        /// <summary>cpu_garments.</summary>
        public uint CpuGarments;
        /// <summary>reserved.</summary>
        public uint Reserved;
        /// <summary>device_name (const char*).</summary>
        public IntPtr DeviceName;
        /// <summary>platform_name (const char*).</summary>
        public IntPtr PlatformName;
        /// <summary>fallback_reason (const char*).</summary>
        public IntPtr FallbackReason;
    }

    /// <summary>drape_opencl_device: one OpenCL device of this machine.</summary>
    [StructLayout(LayoutKind.Sequential)]
    public struct OpenClDeviceInfo
    {
        /// <summary>struct_size.</summary>
        public uint StructSize;
        /// <summary>platform_index.</summary>
        public int PlatformIndex;
        /// <summary>device_index.</summary>
        public int DeviceIndex;
        /// <summary>is_gpu: 1 for a GPU.</summary>
        public uint IsGpu;
        /// <summary>global_mem_bytes.</summary>
        public ulong GlobalMemBytes;
        /// <summary>local_mem_bytes.</summary>
        public ulong LocalMemBytes;
        /// <summary>compute_units.</summary>
        public uint ComputeUnits;
        /// <summary>reserved.</summary>
        public uint Reserved;
        /// <summary>platform_name (const char*, owned by the library for the process' life).</summary>
        public IntPtr PlatformName;
        /// <summary>device_name (const char*).</summary>
        public IntPtr DeviceName;
    }

    /// <summary>The backend in use with its strings copied (<see cref="Context.GetBackendInfo"/>).</summary>
    public sealed class BackendStatus
    {
        /// <summary>The backend last asked for.</summary>
        public Backend Requested { get; internal set; }
        /// <summary>OpenCl when a device runs at least one garment, else Cpu.</summary>
        public Backend Active { get; internal set; }
        /// <summary>Garments stepping on the device.</summary>
        public int OpenClGarments { get; internal set; }
        /// <summary>Garments stepping on the CPU.</summary>
        public int CpuGarments { get; internal set; }
        /// <summary>The OpenCL device's name ("" without one).</summary>
        public string DeviceName { get; internal set; } = "";
        /// <summary>The OpenCL platform's name.</summary>
        public string PlatformName { get; internal set; } = "";
        /// <summary>Why OpenCL was asked for and is not (fully) used; "" otherwise.</summary>
        public string FallbackReason { get; internal set; } = "";
    }

    /// <summary>An OpenCL device with its names copied (<see cref="OpenCl.Devices"/>).</summary>
    public sealed class OpenClDevice
    {
        /// <summary>The raw record.</summary>
        public OpenClDeviceInfo Info { get; internal set; }
        /// <summary>The platform's name.</summary>
        public string PlatformName { get; internal set; } = "";
        /// <summary>The device's name.</summary>
        public string DeviceName { get; internal set; } = "";
    }

    /// <summary>The OpenCL devices of this machine (drape_opencl_device_count / _get).</summary>
    public static unsafe class OpenCl
    {
        /// <summary>Every OpenCL device, in enumeration order (empty without an OpenCL driver).</summary>
        public static IReadOnlyList<OpenClDevice> Devices()
        {
            DrapeLibrary.EnsureCompatible();
            uint n;
            DrapeException.Check(Native.drape_opencl_device_count(&n));
            var list = new List<OpenClDevice>((int)n);
            for (uint k = 0; k < n; ++k)
            {
                OpenClDeviceInfo d = default;
                d.StructSize = (uint)sizeof(OpenClDeviceInfo);
                DrapeException.Check(Native.drape_opencl_device_get(k, &d));
                list.Add(new OpenClDevice
                {
                    Info = d,
                    PlatformName = Utf8.FromNative(d.PlatformName),
                    DeviceName = Utf8.FromNative(d.DeviceName),
                });
            }
            return list;
        }
    }

    public sealed unsafe partial class Context
    {
        /// <summary>Chooses where this context's garments step (drape_context_set_backend). OpenCL
        /// without a working device falls back to the CPU; <see cref="GetBackendInfo"/> says why.</summary>
        public void SetBackend(in BackendDesc desc)
        {
            IntPtr h = Live;
            BackendDesc d = desc;
            DrapeException.Check(Native.drape_context_set_backend(h, &d));
        }

        /// <summary>DRAPE_MAX_STEP_CONTEXTS: the most contexts one <see cref="StepAll"/> takes.</summary>
        public const int MaxStepContexts = 64;

        /// <summary>
        /// Steps several contexts (people) by <paramref name="dt"/> together (drape_step_contexts):
        /// the same as <see cref="Step"/> on each in order, with the same results, but the OpenCL
        /// garments of contexts on one device run their frame in the same launches. Every context
        /// is checked first: when the call throws a <see cref="DrapeException"/> none stepped.
        /// Null, repeated, disposed contexts and a count outside [1, <see cref="MaxStepContexts"/>]
        /// are rejected.
        /// </summary>
        public static void StepAll(IReadOnlyList<Context> contexts, float dt)
        {
            if (contexts == null) throw new ArgumentNullException(nameof(contexts));
            int n = contexts.Count;
            // Past the limit the native call rejects the count; the array still has to exist.
            IntPtr[] handles = new IntPtr[Math.Max(n, 1)];
            for (int i = 0; i < n; ++i)
            {
                if (contexts[i] == null) throw new ArgumentNullException(nameof(contexts), $"contexts[{i}] is null");
                handles[i] = contexts[i].Live;
            }
            fixed (IntPtr* p = handles)
            {
                DrapeException.Check(Native.drape_step_contexts(p, (uint)n, dt));
            }
            for (int i = 0; i < n; ++i) GC.KeepAlive(contexts[i]);
        }

        /// <summary>The backend in use (drape_context_get_backend_info), strings copied.</summary>
        public BackendStatus GetBackendInfo()
        {
            IntPtr h = Live;
            BackendInfo i = default;
            i.StructSize = (uint)sizeof(BackendInfo);
            DrapeException.Check(Native.drape_context_get_backend_info(h, &i));
            return new BackendStatus
            {
                Requested = i.Requested,
                Active = i.Active,
                OpenClGarments = (int)i.OpenclGarments,
                CpuGarments = (int)i.CpuGarments,
                DeviceName = Utf8.FromNative(i.DeviceName),
                PlatformName = Utf8.FromNative(i.PlatformName),
                FallbackReason = Utf8.FromNative(i.FallbackReason),
            };
        }
    }
}
