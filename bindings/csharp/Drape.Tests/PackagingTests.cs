using System;
using System.Collections.Generic;
using System.IO;
using System.IO.Compression;
using System.Linq;
using System.Text.RegularExpressions;
using System.Xml.Linq;
using Xunit;
using Xunit.Abstractions;

namespace Drape.Tests
{
    /// <summary>
    /// `dotnet pack` of bindings/csharp/Drape gives a NuGet package with Drape.dll and the native
    /// library under runtimes/linux-x64/native/, and a .NET program that references only that
    /// package (restored offline from the folder it was packed into) finds and runs the library.
    /// </summary>
    [Collection(SerialCollection.Name)]   // runs dotnet (pack, restore, build): alone, after the rest
    public class PackagingTests
    {
        private readonly ITestOutputHelper _output;

        public PackagingTests(ITestOutputHelper output)
        {
            _output = output;
            TestEnvironment.RequireNativeLibrary();
        }

        private static string DrapeProject => Path.Combine(TestEnvironment.RepoRoot, "bindings", "csharp", "Drape", "Drape.csproj");

        private static string LibraryTfm
        {
            get
            {
                string tf = TestEnvironment.Metadata("DrapeLibraryTargetFramework");
                return tf.Length == 0 ? "netstandard2.1" : tf;
            }
        }

        /// <summary>Packs the Drape project as built for these tests (no build, no restore).</summary>
        private string Pack(string outDir, params string[] extra)
        {
            var args = new List<string>
            {
                "pack", DrapeProject, "--no-build", "-c", TestEnvironment.Metadata("DrapeConfiguration"),
                "-o", outDir, "-nodeReuse:false", "-p:DrapeNativeDir=" + TestEnvironment.NativeDir,
            };
            string tf = TestEnvironment.Metadata("DrapeLibraryTargetFramework");
            if (tf.Length != 0) args.Add("-p:DrapeLibraryTargetFramework=" + tf);
            args.AddRange(extra);
            TestProcess.Result r = TestProcess.Run(TestProcess.Dotnet, args);
            _output.WriteLine(r.Output);
            Assert.True(r.ExitCode == 0, $"dotnet pack failed: {r}");
            string[] packages = Directory.GetFiles(outDir, "*.nupkg");
            Assert.Single(packages);
            return packages[0];
        }

        [Fact]
        public void Pack_PutsTheNativeLibraryUnderRuntimes_AndAConsumerRunsIt()
        {
            if (!OperatingSystem.IsLinux() || System.Runtime.InteropServices.RuntimeInformation.OSArchitecture !=
                System.Runtime.InteropServices.Architecture.X64)
            {
                _output.WriteLine("SKIPPED: the package's native part is checked for linux-x64 builds");
                return;
            }
            using var tmp = new TestProcess.TempDir("drape-pack");
            string feed = Path.Combine(tmp.Path, "feed");
            string nupkg = Pack(feed);
            string version = DrapeLibrary.BindingVersion.ToString();
            Assert.Equal($"Drape.{version}.nupkg", Path.GetFileName(nupkg));

            using (ZipArchive zip = ZipFile.OpenRead(nupkg))
            {
                var names = zip.Entries.Select(e => e.FullName).ToList();
                _output.WriteLine(string.Join("\n", names));
                string nativeEntry = "runtimes/linux-x64/native/libdrape.so";
                Assert.Contains(nativeEntry, names);
                Assert.Contains($"lib/{LibraryTfm}/Drape.dll", names);
                Assert.Contains($"lib/{LibraryTfm}/Drape.xml", names);
                Assert.Contains("PACKAGE.md", names);
                // Only the one native file: not the libdrape.so.0 / .so.0.1.0 symlink names.
                Assert.Single(names, n => n.StartsWith("runtimes/", StringComparison.Ordinal));

                // The bytes are this build's: the library (the file behind the symlinks) and Drape.dll.
                Assert.Equal(File.ReadAllBytes(Path.Combine(TestEnvironment.NativeDir, "libdrape.so")), ReadEntry(zip, nativeEntry));
                Assert.Equal(File.ReadAllBytes(typeof(Context).Assembly.Location), ReadEntry(zip, $"lib/{LibraryTfm}/Drape.dll"));

                // The nuspec: id, the header's version, no dependencies.
                XDocument spec;
                using (var nuspec = new MemoryStream(ReadEntry(zip, "Drape.nuspec"))) spec = XDocument.Load(nuspec);
                XNamespace ns = spec.Root!.Name.Namespace;
                XElement meta = spec.Root.Element(ns + "metadata")!;
                Assert.Equal("Drape", meta.Element(ns + "id")!.Value);
                Assert.Equal(version, meta.Element(ns + "version")!.Value);
                Assert.Empty(meta.Descendants(ns + "dependency"));
            }

            // A consumer that knows nothing of this checkout: a PackageReference, a package source that
            // is the folder above, its own package cache. The runtime must find the native library
            // in the package's runtimes/linux-x64/native/ (copied next to the program at build).
            string app = Path.Combine(tmp.Path, "consumer");
            Directory.CreateDirectory(app);
            File.WriteAllText(Path.Combine(app, "consumer.csproj"),
                "<Project Sdk=\"Microsoft.NET.Sdk\">\n" +
                "  <PropertyGroup><OutputType>Exe</OutputType><TargetFramework>net10.0</TargetFramework>\n" +
                "    <RestorePackagesPath>$(MSBuildThisFileDirectory)packages</RestorePackagesPath></PropertyGroup>\n" +
                $"  <ItemGroup><PackageReference Include=\"Drape\" Version=\"{version}\" /></ItemGroup>\n" +
                "</Project>\n");
            File.WriteAllText(Path.Combine(app, "nuget.config"),
                "<configuration><packageSources><clear />" +
                $"<add key=\"drape-feed\" value=\"{feed}\" /></packageSources></configuration>\n");
            File.WriteAllText(Path.Combine(app, "Program.cs"),
                "using Drape;\n" +
                "using var ctx = new Context();\n" +
                "using Garment shirt = ctx.AddGarment(GarmentTemplate.CreateDefault(GarmentKind.TShirt));\n" +
                "System.Console.WriteLine($\"drape {DrapeLibrary.VersionString} shirt {shirt.VertexCount}\");\n");
            TestProcess.Result run = TestProcess.Run(TestProcess.Dotnet, new[] { "run", "-c", "Release", "-nodeReuse:false" }, app);
            _output.WriteLine(run.Output);
            Assert.True(run.ExitCode == 0, $"the consumer failed: {run}");
            Assert.Matches(new Regex($@"drape {Regex.Escape(version)} shirt \d+"), run.Output);
            Assert.True(File.Exists(Path.Combine(app, "packages", "drape", version, "runtimes", "linux-x64", "native", "libdrape.so")));
        }

        [Fact]
        public void Pack_TakesOtherPlatformsFromARuntimesFolder_AndRefusesToPackNoLibrary()
        {
            using var tmp = new TestProcess.TempDir("drape-pack-rids");
            // Stand-in files for two other platforms, laid out as the package's runtimes/ folder.
            string runtimes = Path.Combine(tmp.Path, "runtimes");
            Directory.CreateDirectory(Path.Combine(runtimes, "win-x64", "native"));
            Directory.CreateDirectory(Path.Combine(runtimes, "osx-arm64", "native"));
            File.WriteAllText(Path.Combine(runtimes, "win-x64", "native", "drape.dll"), "stand-in");
            File.WriteAllText(Path.Combine(runtimes, "osx-arm64", "native", "libdrape.dylib"), "stand-in");
            string nupkg = Pack(Path.Combine(tmp.Path, "out"), "-p:DrapeRuntimesDir=" + runtimes);
            using (ZipArchive zip = ZipFile.OpenRead(nupkg))
            {
                var names = zip.Entries.Select(e => e.FullName).ToList();
                Assert.Contains("runtimes/win-x64/native/drape.dll", names);
                Assert.Contains("runtimes/osx-arm64/native/libdrape.dylib", names);
                if (File.Exists(Path.Combine(TestEnvironment.NativeDir, "libdrape.so")))
                    Assert.Contains(names, n => n.StartsWith("runtimes/linux-", StringComparison.Ordinal) && n.EndsWith("/native/libdrape.so", StringComparison.Ordinal));
            }

            // No library anywhere: an error naming the way out, not a package without its native half.
            var args = new List<string>
            {
                "pack", DrapeProject, "--no-build", "-c", TestEnvironment.Metadata("DrapeConfiguration"),
                "-o", Path.Combine(tmp.Path, "none"), "-nodeReuse:false", "-p:DrapeNativeDir=" + Path.Combine(tmp.Path, "empty"),
            };
            string tf = TestEnvironment.Metadata("DrapeLibraryTargetFramework");
            if (tf.Length != 0) args.Add("-p:DrapeLibraryTargetFramework=" + tf);
            TestProcess.Result r = TestProcess.Run(TestProcess.Dotnet, args);
            Assert.NotEqual(0, r.ExitCode);
            Assert.Contains("no native library to pack", r.Output);
            Assert.Contains("DrapePackWithoutNative", r.Output);
        }

        private static byte[] ReadEntry(ZipArchive zip, string name)
        {
            ZipArchiveEntry entry = zip.GetEntry(name) ?? throw new InvalidOperationException($"{name} is not in the package");
            using Stream s = entry.Open();
            using var m = new MemoryStream();
            s.CopyTo(m);
            return m.ToArray();
        }
    }
}
