using System;
using System.Threading;

namespace Drape
{
    /// <summary>A Drape version (major.minor.patch), unpacked from drape_version().</summary>
    public readonly struct DrapeVersion : IEquatable<DrapeVersion>
    {
        /// <summary>Major: a change here breaks the ABI; the binding refuses another major.</summary>
        public int Major { get; }
        /// <summary>Minor: additions that keep the ABI.</summary>
        public int Minor { get; }
        /// <summary>Patch: fixes.</summary>
        public int Patch { get; }

        /// <summary>Creates a version.</summary>
        public DrapeVersion(int major, int minor, int patch)
        {
            Major = major;
            Minor = minor;
            Patch = patch;
        }

        /// <summary>Unpacks DRAPE_MAKE_VERSION: major &lt;&lt; 22 | minor &lt;&lt; 12 | patch.</summary>
        public static DrapeVersion FromPacked(uint packed) =>
            new DrapeVersion((int)(packed >> 22), (int)((packed >> 12) & 0x3FFu), (int)(packed & 0xFFFu));

        /// <summary>Packs as DRAPE_MAKE_VERSION does.</summary>
        public uint Packed => ((uint)Major << 22) | ((uint)Minor << 12) | (uint)Patch;

        /// <inheritdoc/>
        public bool Equals(DrapeVersion other) => Major == other.Major && Minor == other.Minor && Patch == other.Patch;
        /// <inheritdoc/>
        public override bool Equals(object? obj) => obj is DrapeVersion v && Equals(v);
        /// <inheritdoc/>
        public override int GetHashCode() => HashCode.Combine(Major, Minor, Patch);
        /// <inheritdoc/>
        public override string ToString() => $"{Major}.{Minor}.{Patch}";
    }

    /// <summary>Thrown on first use when the loaded native library's major version is not the
    /// one this binding was written for (the ABI may differ: calling on would corrupt memory).</summary>
    public sealed class DrapeVersionMismatchException : Exception
    {
        /// <summary>The loaded library's version.</summary>
        public DrapeVersion NativeVersion { get; }
        /// <summary>The major version this binding needs.</summary>
        public int ExpectedMajor { get; }

        internal DrapeVersionMismatchException(DrapeVersion nativeVersion, int expectedMajor)
            : base($"Drape: the native library is version {nativeVersion}, but these C# bindings were " +
                   $"written for major version {expectedMajor} (header {DrapeLibrary.BindingVersion}). " +
                   "Use a libdrape built from the same Drape release as Drape.dll.")
        {
            NativeVersion = nativeVersion;
            ExpectedMajor = expectedMajor;
        }
    }

    /// <summary>Library-wide queries: version, compatibility check, result names, leak reports.</summary>
    public static class DrapeLibrary
    {
        /// <summary>The major version the binding needs (DRAPE_VERSION_MAJOR of its header).</summary>
        public const int ExpectedMajor = (int)Native.HeaderVersionMajor;

        /// <summary>The header version the binding was written against.</summary>
        public static DrapeVersion BindingVersion =>
            new DrapeVersion((int)Native.HeaderVersionMajor, (int)Native.HeaderVersionMinor, (int)Native.HeaderVersionPatch);

        /// <summary>The loaded native library's version (drape_version()). Loads the library but
        /// does not check it (see <see cref="EnsureCompatible"/>).</summary>
        public static DrapeVersion Version => DrapeVersion.FromPacked(CallVersion());

        /// <summary>The native "major.minor.patch" string (drape_version_string()).</summary>
        public static string VersionString
        {
            get
            {
                CallVersion();  // a clear message if the library is missing
                return Utf8.FromNative(Native.drape_version_string());
            }
        }

        /// <summary>The static name of a result code ("DRAPE_OK", ...; drape_result_name()).</summary>
        public static string ResultName(ResultCode code)
        {
            CallVersion();
            return Utf8.FromNative(Native.drape_result_name(code));
        }

        private static int s_compatible;  // 1 once the check has passed

        /// <summary>Loads the native library and checks that its major version is <see cref="ExpectedMajor"/>.
        /// Runs once; every Context, Recording and CreateDefault calls it first, so an application
        /// never needs to. Throws <see cref="DllNotFoundException"/> (with a hint where to put the
        /// library) or <see cref="DrapeVersionMismatchException"/>.</summary>
        public static void EnsureCompatible()
        {
            if (Volatile.Read(ref s_compatible) == 1) return;
            CheckCompatible(CallVersion());
            Volatile.Write(ref s_compatible, 1);
        }

        /// <summary>The check itself, separate so tests can feed it another version.</summary>
        internal static void CheckCompatible(uint packedNativeVersion)
        {
            DrapeVersion v = DrapeVersion.FromPacked(packedNativeVersion);
            if (v.Major != ExpectedMajor) throw new DrapeVersionMismatchException(v, ExpectedMajor);
        }

        private static uint CallVersion()
        {
            try
            {
                return Native.drape_version();
            }
            catch (DllNotFoundException e)
            {
                throw new DllNotFoundException(
                    $"Drape: the native library '{Native.LibraryName}' could not be loaded (libdrape.so on Linux " +
                    "and Android, libdrape.dylib on macOS, drape.dll on Windows). Put it next to the application " +
                    "(or in the Unity project's Plugins folder for its platform) or on the loader's search path. " +
                    "Loader message: " + e.Message, e);
            }
            catch (EntryPointNotFoundException e)
            {
                throw new EntryPointNotFoundException(
                    $"Drape: a library named '{Native.LibraryName}' was loaded but has no drape_version(): " +
                    "it is not libdrape, or not one these bindings can use. Loader message: " + e.Message, e);
            }
        }

        // ---- Leaks -------------------------------------------------------------------------------
        //
        // Native objects are destroyed only by Dispose(), on the thread that uses them: the C ABI
        // allows one thread at a time per context, and the finalizer thread is another thread
        // (and during shutdown or a Unity domain reload the library may be mid-teardown). So a
        // Context or Recording that is garbage-collected without Dispose() is NOT freed; its
        // finalizer only counts it here and calls HandleLeaked. That is a bug in the application:
        // dispose them (`using`, or in OnDestroy/OnDisable in Unity).

        private static long s_leaked;

        /// <summary>How many Context/Recording objects were garbage-collected without Dispose()
        /// (their native memory stays allocated until the process ends).</summary>
        public static long LeakedHandleCount => Interlocked.Read(ref s_leaked);

        /// <summary>Called on the GC finalizer thread with a description, each time a leak is
        /// counted. Keep the handler short and thread-safe; exceptions from it are swallowed.
        /// Unity: e.g. <c>DrapeLibrary.HandleLeaked += m => UnityEngine.Debug.LogWarning(m);</c></summary>
        public static event Action<string>? HandleLeaked;

        internal static void ReportLeak(string what)
        {
            Interlocked.Increment(ref s_leaked);
            try
            {
                HandleLeaked?.Invoke($"Drape: a {what} was garbage-collected without Dispose(); its native memory " +
                                     "is leaked (native objects are never freed from the finalizer thread).");
            }
            catch
            {
                // Never let a handler's exception escape a finalizer (it would end the process).
            }
        }
    }
}
