using System;
using System.IO;
using System.Text.RegularExpressions;
using Xunit;
using Xunit.Abstractions;

namespace Drape.Tests
{
    /// <summary>samples/csharp (Drape.Sample) is referenced by this project, so it is built with the
    /// tests; here its Program runs in-process on its default recording and on bad options.</summary>
    public class SampleTests
    {
        private readonly ITestOutputHelper _output;

        public SampleTests(ITestOutputHelper output)
        {
            _output = output;
            TestEnvironment.RequireNativeLibrary();
        }

        private static (int Code, string Out, string Err) Run(params string[] args)
        {
            var o = new StringWriter();
            var e = new StringWriter();
            int code = Drape.Sample.Program.Run(args, o, e);
            return (code, o.ToString(), e.ToString());
        }

        [Fact]
        public void Sample_ReplaysTheBundledRecording_AndPrintsEveryStage()
        {
            // The default recording is copied next to the sample's (and so the tests') assembly.
            Assert.True(File.Exists(Path.Combine(AppContext.BaseDirectory, "data", "Ges01_wavehand.csv")));
            var (code, output, error) = Run("--frames", "40", "--every", "10", "--particles", "600");
            _output.WriteLine(output);
            Assert.True(code == 0, error);
            Assert.Equal("", error);
            Assert.Contains("Ges01_wavehand.csv", output);
            Assert.Contains("40 frames accepted, 0 rejected", output);
            Assert.Contains("40 cloth steps", output);
            foreach (string stage in new[] { "skeleton", "body", "proxies", "cloth step", "  integrate", "  collide", "frame (C#)" })
                Assert.Matches(new Regex("^" + Regex.Escape(stage) + @"\s+\d+\.\d{3}\s+\d+\.\d{3}\s+\d+\.\d{3}\s+\d+\.\d{3}\r?$", RegexOptions.Multiline), output);
            // Per-frame lines at 0, 10, 20, 30 and the last frame.
            Assert.Equal(5, Regex.Matches(output, @"^\s+\d+\s+\d+\.\d{3}(\s+\d+\.\d{3}){7}\s+\d+\r?$", RegexOptions.Multiline).Count);
        }

        [Fact]
        public void Sample_WithoutGarment_AndQuiet()
        {
            var (code, output, error) = Run("--garment", "none", "--frames", "5", "--quiet");
            Assert.True(code == 0, error);
            Assert.Contains("no garment", output);
            Assert.DoesNotContain("cloth step", output);
            Assert.DoesNotContain("integrate", output);
        }

        [Fact]
        public void Sample_RefusesBadOptions_AndMissingFiles()
        {
            Assert.Equal(2, Run("--frames", "0").Code);
            Assert.Equal(2, Run("--garment", "hat").Code);
            Assert.Equal(2, Run("--bogus").Code);
            Assert.Equal(2, Run("--garment", "none", "--particles", "500").Code);
            var (code, _, error) = Run("--recording", "/nonexistent/take.csv");
            Assert.Equal(1, code);
            Assert.Contains("/nonexistent/take.csv", error);
            var help = Run("--help");
            Assert.Equal(0, help.Code);
            Assert.Contains("--recording", help.Out);
        }
    }
}
