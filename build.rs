//! Compiles every `glsl/*.comp` to SPIR-V with shaderc; `src/gpu/shaders.rs` embeds the results.
//! Shaders include `glsl/*.glsl` and `glsl/shared.h`, so any change under glsl/ rebuilds them.

use std::path::{Path, PathBuf};

fn main() {
    link_static_glslang();
    let glsl = Path::new("glsl");
    println!("cargo:rerun-if-changed=glsl");
    let out = PathBuf::from(std::env::var("OUT_DIR").expect("cargo sets OUT_DIR"));
    let compiler = shaderc::Compiler::new().expect("shaderc compiler");
    let mut entries: Vec<_> = std::fs::read_dir(glsl)
        .expect("glsl/ directory")
        .map(|e| e.expect("glsl/ entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "comp"))
        .collect();
    entries.sort();
    for path in entries {
        let source = std::fs::read_to_string(&path).expect("read shader");
        let mut options = shaderc::CompileOptions::new().expect("shaderc options");
        options.set_target_env(shaderc::TargetEnv::Vulkan, shaderc::EnvVersion::Vulkan1_2 as u32);
        options.set_target_spirv(shaderc::SpirvVersion::V1_5);
        options.set_optimization_level(shaderc::OptimizationLevel::Performance);
        options.set_generate_debug_info();
        options.set_include_callback(|name, _, _, _| {
            let file = glsl.join(name);
            let content = std::fs::read_to_string(&file)
                .map_err(|e| format!("cannot include {}: {e}", file.display()))?;
            Ok(shaderc::ResolvedInclude { resolved_name: file.display().to_string(), content })
        });
        let name = path.file_name().unwrap().to_string_lossy().to_string();
        let artifact = compiler
            .compile_into_spirv(&source, shaderc::ShaderKind::Compute, &name, "main", Some(&options))
            .unwrap_or_else(|e| panic!("shader {name} failed to compile:\n{e}"));
        let stem = path.file_stem().unwrap().to_string_lossy();
        std::fs::write(out.join(format!("{stem}.spv")), artifact.as_binary_u8()).expect("write spv");
    }
}

/// shaderc-sys links `libshaderc_combined.a`, which on Debian does not carry glslang and
/// SPIRV-Tools; those come from their own static archives.
fn link_static_glslang() {
    let dir = std::env::var("SHADERC_LIB_DIR").unwrap_or_else(|_| "/usr/lib/x86_64-linux-gnu".into());
    println!("cargo:rustc-link-search=native={dir}");
    for lib in [
        "glslang",
        "MachineIndependent",
        "GenericCodeGen",
        "OSDependent",
        "OGLCompiler",
        "SPIRV",
        "glslang-default-resource-limits",
        "SPIRV-Tools-opt",
        "SPIRV-Tools",
    ] {
        println!("cargo:rustc-link-lib=static={lib}");
    }
    println!("cargo:rustc-link-lib=dylib=stdc++");
}
