// A small xunit runner for Mono: finds the [Fact] and [Theory] methods of a test assembly by reflection
// and runs them one after the other, each on a fresh instance of its class (constructor with an
// ITestOutputHelper or none; Dispose afterwards), the rows of a theory from its data attributes
// ([InlineData], [MemberData]). Classes in a [Collection] run last, as xunit runs its
// non-parallel collections. Compiled by Mono's mcs (C# 7 at most): no newer syntax here.
//   mono MonoTestRunner.exe [Drape.Tests.Mono.dll] [--filter TEXT] [--verbose]
// Exit code: 0 when every test passed, 1 otherwise, 2 for bad arguments.
using System;
using System.Collections.Generic;
using System.Diagnostics;
using System.IO;
using System.Linq;
using System.Reflection;
using System.Text;
using System.Threading.Tasks;
using Xunit.Abstractions;

internal sealed class OutputHelper : ITestOutputHelper
{
    public readonly StringBuilder Text = new StringBuilder();
    public void WriteLine(string message) { lock (Text) Text.AppendLine(message); }
    public void WriteLine(string format, params object[] args) { lock (Text) Text.AppendLine(string.Format(format, args)); }
}

internal static class MonoTestRunner
{
    private static bool Is(object attribute, string name)
    {
        for (Type t = attribute.GetType(); t != null; t = t.BaseType)
            if (t.FullName == name) return true;
        return false;
    }

    private static Exception Unwrap(Exception e)
    {
        while ((e is TargetInvocationException || e is AggregateException) && e.InnerException != null) e = e.InnerException;
        return e;
    }

    private static string Describe(object[] row)
    {
        if (row == null || row.Length == 0) return "";
        return "(" + string.Join(", ", row.Select(v => v == null ? "null" : v is string ? "\"" + v + "\"" : v.ToString())) + ")";
    }

    private static int Main(string[] args)
    {
        string assemblyPath = null, filter = null;
        bool verbose = false;
        for (int i = 0; i < args.Length; ++i)
        {
            if (args[i] == "--filter" && i + 1 < args.Length) filter = args[++i];
            else if (args[i] == "--verbose") verbose = true;
            else if (!args[i].StartsWith("--", StringComparison.Ordinal) && assemblyPath == null) assemblyPath = args[i];
            else
            {
                Console.Error.WriteLine("usage: mono MonoTestRunner.exe [TESTS.dll] [--filter TEXT] [--verbose]");
                return 2;
            }
        }
        if (assemblyPath == null) assemblyPath = Path.Combine(AppDomain.CurrentDomain.BaseDirectory, "Drape.Tests.Mono.dll");
        Assembly tests = Assembly.LoadFrom(assemblyPath);
        Console.WriteLine("MonoTestRunner: " + Path.GetFileName(assemblyPath) + " on Mono " + MonoVersion() +
                          " (" + Environment.Version + ", " + IntPtr.Size * 8 + "-bit)");

        var classes = tests.GetTypes()
            .Where(t => t.IsClass && t.IsPublic && !t.IsAbstract)
            .OrderBy(t => t.GetCustomAttributes(true).Any(a => Is(a, "Xunit.CollectionAttribute")) ? 1 : 0)
            .ThenBy(t => t.FullName, StringComparer.Ordinal)
            .ToList();
        int passed = 0, failed = 0, skipped = 0, withSkipNote = 0;
        var failures = new List<string>();
        var total = Stopwatch.StartNew();
        foreach (Type type in classes)
        {
            foreach (MethodInfo method in type.GetMethods(BindingFlags.Public | BindingFlags.Instance).OrderBy(m => m.MetadataToken))
            {
                object[] attributes = method.GetCustomAttributes(true);
                object fact = attributes.FirstOrDefault(a => Is(a, "Xunit.FactAttribute"));
                if (fact == null) continue;
                string name = type.FullName + "." + method.Name;
                if (filter != null && name.IndexOf(filter, StringComparison.Ordinal) < 0) continue;
                string skip = (string)fact.GetType().GetProperty("Skip").GetValue(fact, null);
                if (!string.IsNullOrEmpty(skip))
                {
                    skipped++;
                    Console.WriteLine("SKIP  " + name + ": " + skip);
                    continue;
                }
                var rows = new List<object[]>();
                if (Is(fact, "Xunit.TheoryAttribute"))
                {
                    foreach (object data in attributes.Where(a => Is(a, "Xunit.Sdk.DataAttribute")))
                    {
                        var got = (IEnumerable<object[]>)data.GetType().GetMethod("GetData", new[] { typeof(MethodInfo) })
                                                            .Invoke(data, new object[] { method });
                        rows.AddRange(got);
                    }
                }
                else
                {
                    rows.Add(new object[0]);
                }

                foreach (object[] row in rows)
                {
                    string display = name + Describe(row);
                    var output = new OutputHelper();
                    var clock = Stopwatch.StartNew();
                    Exception error = null;
                    object instance = null;
                    try
                    {
                        ConstructorInfo withOutput = type.GetConstructor(new[] { typeof(ITestOutputHelper) });
                        instance = withOutput != null ? withOutput.Invoke(new object[] { output }) : Activator.CreateInstance(type);
                        object result = method.Invoke(instance, row);
                        var task = result as Task;
                        if (task != null) task.GetAwaiter().GetResult();
                    }
                    catch (Exception e)
                    {
                        error = Unwrap(e);
                    }
                    finally
                    {
                        var disposable = instance as IDisposable;
                        if (disposable != null)
                        {
                            try { disposable.Dispose(); }
                            catch (Exception e) { if (error == null) error = Unwrap(e); }
                        }
                    }
                    clock.Stop();
                    string text = output.Text.ToString();
                    if (error == null)
                    {
                        passed++;
                        bool note = text.Contains("SKIPPED:");
                        if (note) withSkipNote++;
                        Console.WriteLine("PASS  " + display + " (" + clock.ElapsedMilliseconds + " ms)" + (note ? " [wrote SKIPPED]" : ""));
                        if (verbose || note)
                            foreach (string line in text.Split('\n').Where(l => l.Trim().Length > 0)) Console.WriteLine("        " + line.TrimEnd());
                    }
                    else
                    {
                        failed++;
                        failures.Add(display);
                        Console.WriteLine("FAIL  " + display + " (" + clock.ElapsedMilliseconds + " ms)");
                        Console.WriteLine("        " + error.GetType().FullName + ": " + error.Message.Replace("\n", "\n        "));
                        Console.WriteLine("        " + (error.StackTrace ?? "").Replace("\n", "\n        "));
                        if (text.Length > 0) Console.WriteLine("        output:\n        " + text.TrimEnd().Replace("\n", "\n        "));
                    }
                }
            }
        }
        Console.WriteLine();
        Console.WriteLine("MonoTestRunner: " + passed + " passed (" + withSkipNote + " of them wrote SKIPPED), " + failed +
                          " failed, " + skipped + " skipped, in " + total.Elapsed.TotalSeconds.ToString("0.0") + " s");
        foreach (string f in failures) Console.WriteLine("  failed: " + f);
        return failed == 0 ? 0 : 1;
    }

    private static string MonoVersion()
    {
        Type mono = Type.GetType("Mono.Runtime");
        if (mono == null) return "(not Mono)";
        MethodInfo display = mono.GetMethod("GetDisplayName", BindingFlags.NonPublic | BindingFlags.Static);
        return display != null ? (string)display.Invoke(null, null) : "?";
    }
}
