using System;
using System.Collections.Generic;
using System.Diagnostics;
using System.IO;
using System.Text;

namespace Drape.Tests
{
    /// <summary>Runs a child process (dotnet pack, drape-replay, bash, cc) and collects its output.</summary>
    internal static class TestProcess
    {
        public sealed class Result
        {
            public int ExitCode;
            public string Output = "";
            public override string ToString() => $"exit code {ExitCode}:\n{Output}";
        }

        /// <summary>The dotnet host running these tests (DOTNET_HOST_PATH, set by the SDK), else "dotnet".</summary>
        public static string Dotnet
        {
            get
            {
                string? host = Environment.GetEnvironmentVariable("DOTNET_HOST_PATH");
                return !string.IsNullOrEmpty(host) && File.Exists(host) ? host : "dotnet";
            }
        }

        /// <summary>The first of <paramref name="names"/> found on PATH, or null.</summary>
        public static string? FindOnPath(params string[] names)
        {
            string[] dirs = (Environment.GetEnvironmentVariable("PATH") ?? "").Split(Path.PathSeparator);
            foreach (string n in names)
                foreach (string d in dirs)
                {
                    if (d.Length == 0) continue;
                    string p = Path.Combine(d, n);
                    if (File.Exists(p)) return p;
                }
            return null;
        }

        public static Result Run(string file, IEnumerable<string> args, string? workingDirectory = null,
                                 int timeoutMs = 300_000, IDictionary<string, string>? environment = null)
        {
            var psi = new ProcessStartInfo(file)
            {
                RedirectStandardOutput = true,
                RedirectStandardError = true,
                UseShellExecute = false,
                WorkingDirectory = workingDirectory ?? Environment.CurrentDirectory,
            };
#if NETCOREAPP
            foreach (string a in args) psi.ArgumentList.Add(a);
#else
            // Mono 6 has ProcessStartInfo.ArgumentList but ignores it: quote into Arguments.
            psi.Arguments = string.Join(" ", System.Linq.Enumerable.Select(args, Quote));
#endif
            // A child dotnet must not inherit the test host's MSBuild settings.
            foreach (string v in new[] { "MSBuildExtensionsPath", "MSBuildSDKsPath", "MSBUILD_EXE_PATH", "MSBuildLoadMicrosoftTargetsReadOnly" })
                psi.Environment.Remove(v);
            psi.Environment["DOTNET_CLI_TELEMETRY_OPTOUT"] = "1";
            psi.Environment["DOTNET_NOLOGO"] = "1";
            psi.Environment["DOTNET_SKIP_FIRST_TIME_EXPERIENCE"] = "1";
            if (environment != null)
                foreach (var kv in environment) psi.Environment[kv.Key] = kv.Value;

            var output = new StringBuilder();
            using var p = new Process { StartInfo = psi };
            p.OutputDataReceived += (_, e) => { if (e.Data != null) lock (output) output.AppendLine(e.Data); };
            p.ErrorDataReceived += (_, e) => { if (e.Data != null) lock (output) output.AppendLine(e.Data); };
            p.Start();
            p.BeginOutputReadLine();
            p.BeginErrorReadLine();
            if (!p.WaitForExit(timeoutMs))
            {
#if NETCOREAPP
                try { p.Kill(entireProcessTree: true); } catch (InvalidOperationException) { }
#else
                try { p.Kill(); } catch (InvalidOperationException) { }
#endif
                throw new TimeoutException($"{file} {string.Join(" ", args)} ran over {timeoutMs / 1000} s:\n{output}");
            }
            p.WaitForExit();
            lock (output) return new Result { ExitCode = p.ExitCode, Output = output.ToString() };
        }

        private static string Quote(string a) =>
            a.Length > 0 && a.IndexOfAny(new[] { ' ', '\t', '"', '\\', '\'' }) < 0 ? a : "\"" + a.Replace("\\", "\\\\").Replace("\"", "\\\"") + "\"";

        /// <summary>A fresh temporary directory, deleted by Dispose.</summary>
        public sealed class TempDir : IDisposable
        {
            public string Path { get; }
            public TempDir(string prefix)
            {
                Path = System.IO.Path.Combine(System.IO.Path.GetTempPath(), $"{prefix}-{Guid.NewGuid():N}");
                Directory.CreateDirectory(Path);
            }
            public void Dispose()
            {
                try { Directory.Delete(Path, recursive: true); } catch (IOException) { } catch (UnauthorizedAccessException) { }
            }
        }
    }
}
