// What the tests use from .NET (Core) that .NET Standard 2.1 lacks, for the Mono build only. Inside
// namespace Drape.Tests these names win over System's, so the test sources compile unchanged.
#if DRAPE_MONO
using System;
using System.Runtime.InteropServices;

namespace Drape.Tests
{
    internal static class OperatingSystem
    {
        public static bool IsWindows() => RuntimeInformation.IsOSPlatform(OSPlatform.Windows);
        public static bool IsMacOS() => RuntimeInformation.IsOSPlatform(OSPlatform.OSX);
        public static bool IsLinux() => RuntimeInformation.IsOSPlatform(OSPlatform.Linux);
    }

    /// <summary>System.Runtime.InteropServices.NativeLibrary's three calls the tests make, over dlopen.</summary>
    internal static class NativeLibrary
    {
        private const int RtldNow = 2;

        [DllImport("libdl.so.2")] private static extern IntPtr dlopen(string fileName, int flags);
        [DllImport("libdl.so.2")] private static extern IntPtr dlsym(IntPtr handle, string name);
        [DllImport("libdl.so.2")] private static extern int dlclose(IntPtr handle);
        [DllImport("libdl.so.2")] private static extern IntPtr dlerror();

        public static IntPtr Load(string path)
        {
            IntPtr h = dlopen(path, RtldNow);
            if (h == IntPtr.Zero)
                throw new DllNotFoundException($"dlopen({path}) failed: {Marshal.PtrToStringAnsi(dlerror())}");
            return h;
        }

        public static bool TryGetExport(IntPtr handle, string name, out IntPtr address)
        {
            address = dlsym(handle, name);
            return address != IntPtr.Zero;
        }

        public static void Free(IntPtr handle) => dlclose(handle);
    }
}
#endif
