using System;
using System.IO;
using System.Reflection;
using System.Runtime.Loader;
using Xunit;
using Xunit.Abstractions;

namespace Drape.Tests
{
    /// <summary>
    /// The major-version check on first use, end to end: a stand-in libdrape whose drape_version()
    /// reports another major (built with the C compiler from a few lines of C) is bound to a second
    /// copy of Drape.dll in its own AssemblyLoadContext. Every first use (a Context, a Recording, a
    /// CreateDefault) must throw DrapeVersionMismatchException, and before any other native call:
    /// the stand-in exports nothing else, so calling anything else would throw EntryPointNotFound.
    /// </summary>
    public class FirstUseVersionCheckTests
    {
        private readonly ITestOutputHelper _output;

        public FirstUseVersionCheckTests(ITestOutputHelper output) => _output = output;

        private sealed class StandInContext : AssemblyLoadContext
        {
            private readonly string _drapeDll, _nativeLib;

            public StandInContext(string drapeDll, string nativeLib) : base("drape-version-check", isCollectible: true)
            {
                _drapeDll = drapeDll;
                _nativeLib = nativeLib;
            }

            protected override Assembly? Load(AssemblyName name) =>
                name.Name == "Drape" ? LoadFromAssemblyPath(_drapeDll) : null;

            protected override IntPtr LoadUnmanagedDll(string unmanagedDllName) =>
                unmanagedDllName.Contains("drape") ? LoadUnmanagedDllFromPath(_nativeLib) : IntPtr.Zero;
        }

        private static Exception Unwrap(Exception e) => e is TargetInvocationException t && t.InnerException != null ? t.InnerException : e;

        [Fact]
        public void AnotherMajor_IsRefusedOnFirstUse_BeforeAnyOtherNativeCall()
        {
            if (!OperatingSystem.IsLinux())
            {
                _output.WriteLine("SKIPPED: the stand-in library is built as a Linux shared object");
                return;
            }
            string? cc = TestProcess.FindOnPath("cc", "gcc", "clang");
            if (cc == null)
            {
                _output.WriteLine("SKIPPED: no C compiler (cc, gcc, clang) on PATH to build the stand-in library");
                return;
            }
            using var dir = new TestProcess.TempDir("drape-version");
            int otherMajor = DrapeLibrary.ExpectedMajor + 1;
            string src = Path.Combine(dir.Path, "standin.c");
            File.WriteAllText(src,
                "#include <stdint.h>\n" +
                $"uint32_t drape_version(void) {{ return ((uint32_t){otherMajor} << 22) | (3u << 12) | 7u; }}\n" +
                $"const char* drape_version_string(void) {{ return \"{otherMajor}.3.7\"; }}\n");
            string lib = Path.Combine(dir.Path, "libdrape.so");
            TestProcess.Result built = TestProcess.Run(cc, new[] { "-shared", "-fPIC", "-o", lib, src });
            Assert.True(built.ExitCode == 0, $"building the stand-in failed: {built}");

            var alc = new StandInContext(typeof(Context).Assembly.Location, lib);
            try
            {
                Assembly drape = alc.LoadFromAssemblyName(new AssemblyName("Drape"));
                Assert.NotSame(typeof(Context).Assembly, drape);
                Type library = drape.GetType("Drape.DrapeLibrary", throwOnError: true)!;

                // The version itself can be read (drape_version exists): it is the stand-in's.
                object version = library.GetProperty("Version")!.GetValue(null)!;
                Assert.Equal($"{otherMajor}.3.7", version.ToString());

                void ExpectMismatch(string what, Func<object?> firstUse)
                {
                    Exception e = Assert.ThrowsAny<Exception>(() => firstUse());
                    e = Unwrap(e);
                    Assert.True(e.GetType().FullName == "Drape.DrapeVersionMismatchException",
                        $"{what}: expected DrapeVersionMismatchException, got {e.GetType().FullName}: {e.Message}");
                    Assert.Contains($"{otherMajor}.3.7", e.Message);
                    Assert.Contains($"major version {DrapeLibrary.ExpectedMajor}", e.Message);
                    _output.WriteLine($"{what}: {e.Message}");
                }

                Type context = drape.GetType("Drape.Context", throwOnError: true)!;
                ExpectMismatch("new Context()", () => Activator.CreateInstance(context));
                Type recording = drape.GetType("Drape.Recording", throwOnError: true)!;
                Type layout = drape.GetType("Drape.Layout", throwOnError: true)!;
                ExpectMismatch("Recording.Open", () => recording.GetMethod("Open")!.Invoke(null, new[] { "x.csv", Enum.ToObject(layout, 0) }));
                foreach (string type in new[] { "ContextDesc", "BodyShape", "GarmentDesc", "ClothParams", "MeshFit" })
                {
                    Type t = drape.GetType("Drape." + type, throwOnError: true)!;
                    ExpectMismatch(type + ".CreateDefault", () => t.GetMethod("CreateDefault")!.Invoke(null, null));
                }
                // A failed check is not remembered as passed: it throws every time.
                ExpectMismatch("EnsureCompatible again", () => library.GetMethod("EnsureCompatible")!.Invoke(null, null));
            }
            finally
            {
                alc.Unload();
            }

            // This process's own binding is unaffected.
            TestEnvironment.RequireNativeLibrary();
            DrapeLibrary.EnsureCompatible();
        }
    }
}
