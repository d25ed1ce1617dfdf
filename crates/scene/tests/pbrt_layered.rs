//! pbrt-v4's coated materials (`coateddiffuse`, `coatedconductor`) and `mix`: their
//! parameters as pbrt-v4 reads them, textured ones read at each point, and furnaces.

use glam::DVec3;
use pathlab_testkit::render::assert_mean;

mod pbrt_common;
use pbrt_common::{load_text, render_film, FURNACE};

#[test]
fn coated_materials_read_their_layers_and_a_lossless_coat_vanishes_in_a_furnace() {
    use pathlab_render::desc::{CoatedBase, MaterialDesc, TextureDesc};
    let scene = FURNACE.to_string()
        + r#"MakeNamedMaterial "plastic" "string type" "coateddiffuse" "rgb reflectance" [ 0.2 0.4 0.6 ]
  "float roughness" 0.04 "float thickness" 0.2 "rgb albedo" [ 0.5 0.5 0.5 ] "float g" 0.3
  "integer maxdepth" 20 "integer nsamples" 2 "float eta" 1.4
MakeNamedMaterial "gold" "string type" "coatedconductor" "float interface.roughness" 0.01
  "spectrum conductor.eta" "metal-Au-eta" "spectrum conductor.k" "metal-Au-k"
  "float conductor.uroughness" 0.09 "float conductor.vroughness" 0.16 "bool remaproughness" false
Material "coateddiffuse" "rgb reflectance" [ 1 1 1 ] "integer maxdepth" 1000 "float thickness" 1e-30
Shape "sphere" "float radius" 1
"#;
    let desc = load_text("coated", &[("coated.pbrt", &scene)]).unwrap();
    assert!(desc.warnings.is_empty(), "{:?}", desc.warnings);
    let MaterialDesc::Coated(plastic) = &desc.materials[0] else {
        panic!("{:?}", desc.materials[0]);
    };
    let number = |a: f32| [TextureDesc::value(a), TextureDesc::value(a)];
    assert_eq!(plastic.coat_alpha, number(0.2));
    assert_eq!(
        (plastic.coat_eta, &plastic.thickness, &plastic.g),
        (1.4, &TextureDesc::value(0.2), &TextureDesc::value(0.3))
    );
    assert_eq!((plastic.max_depth, plastic.samples), (20, 2));
    assert_eq!(plastic.albedo, TextureDesc::value(0.5));
    assert!(
        matches!(&plastic.base, CoatedBase::Diffuse(t) if t.as_constant() == Some(glam::Vec3::new(0.2, 0.4, 0.6)))
    );
    let MaterialDesc::Coated(gold) = &desc.materials[1] else {
        panic!("{:?}", desc.materials[1]);
    };
    // remaproughness false: the coat's roughness is its α.
    assert_eq!(gold.coat_alpha, number(0.01));
    assert_eq!(
        (gold.coat_eta, &gold.thickness, gold.max_depth, gold.samples),
        (1.5, &TextureDesc::value(0.01), 10, 1)
    );
    let CoatedBase::Conductor { eta, alpha, .. } = &gold.base else {
        panic!("{:?}", gold.base);
    };
    assert_eq!(*alpha, [TextureDesc::value(0.09), TextureDesc::value(0.16)]);
    assert!(eta.x < 0.5 && eta.z > 1.0, "gold's η {eta}");
    // A white Lambertian under a smooth coat, with no medium and no thickness to absorb in,
    // returns all the light it receives: under a uniform sky the sphere's radiance is the
    // sky's, 1. (pbrt-v4's default thickness 0.01 absorbs a little at each crossing.)
    let film = render_film(&desc, 64, 5);
    assert!(film.image_mean_std_error().y < 0.01);
    assert_mean("coated furnace", &film, DVec3::ONE);
}

#[test]
fn coats_and_their_bases_take_textured_roughness() {
    use glam::{Vec2, Vec3};
    use pathlab_render::desc::{CoatedBase, MaterialDesc, TextureDesc};
    use pathlab_render::texture::{Tex, TexPoint};
    let desc = load_text(
        "coat-roughness",
        &[(
            "r.pbrt",
            r#"WorldBegin
Texture "ramp" "float" "bilerp"
MakeNamedMaterial "plastic" "string type" "coateddiffuse" "texture roughness" "ramp"
MakeNamedMaterial "gold" "string type" "coatedconductor" "texture interface.uroughness" "ramp" "float interface.vroughness" 0.2 "bool remaproughness" false
MakeNamedMaterial "copper" "string type" "coatedconductor" "texture conductor.roughness" "ramp"
NamedMaterial "plastic"
Shape "sphere"
"#,
        )],
    )
    .unwrap();
    assert!(desc.warnings.is_empty(), "{:?}", desc.warnings);
    let alphas = |m: &MaterialDesc| match m {
        MaterialDesc::Coated(c) => c.coat_alpha.clone().map(|t| Tex::from_desc(&t)),
        other => panic!("not coated: {other:?}"),
    };
    let at = |t: &Tex, v: f32| t.eval(&TexPoint::uv(Vec2::new(0.3, v)));
    let close = |a: Vec3, b: f32| (a - Vec3::splat(b)).abs().max_element() < 1e-6;
    // α = √roughness along the bilerp's v, on both axes.
    let [u, v] = alphas(&desc.materials[0]);
    assert!(close(at(&u, 0.25), 0.5) && close(at(&v, 0.64), 0.8));
    // The interface's roughness, not remapped, v given as a number.
    let [u, v] = alphas(&desc.materials[1]);
    assert!(close(at(&u, 0.25), 0.25) && close(at(&v, 0.7), 0.2));
    // The base conductor's roughness, remapped; the coat smooth.
    let MaterialDesc::Coated(copper) = &desc.materials[2] else {
        panic!("{:?}", desc.materials[2]);
    };
    let CoatedBase::Conductor { alpha, .. } = &copper.base else {
        panic!("{:?}", copper.base);
    };
    let [u, v] = alpha.clone().map(|t| Tex::from_desc(&t));
    assert!(close(at(&u, 0.25), 0.5) && close(at(&v, 0.64), 0.8));
    assert_eq!(
        copper.coat_alpha,
        [TextureDesc::value(0.0), TextureDesc::value(0.0)]
    );
}

#[test]
fn coats_of_textured_parameters_render_as_coats_of_those_numbers() {
    // A bilerp texture of one value cannot be folded to a number, so the coat's roughness
    // (then the base's, then the medium's parameters) is looked up at each point; it must
    // render what the number renders.
    let scene = |roughness: &str| {
        FURNACE.replace("LightSource \"infinite\" \"rgb L\" [ 1 1 1 ]", "LightSource \"infinite\" \"rgb L\" [ 0.2 0.2 0.2 ]\nLightSource \"distant\" \"point3 from\" [ 1 2 3 ] \"rgb L\" [ 3 3 3 ]")
            + &format!(
                r#"Texture "flat" "float" "bilerp" "float v00" 0.04 "float v01" 0.04 "float v10" 0.04 "float v11" 0.04
Material "coateddiffuse" "rgb reflectance" [ 0.2 0.4 0.6 ] {roughness}
Shape "sphere"
"#
            )
    };
    let textured = load_text(
        "coat-textured",
        &[("s.pbrt", &scene(r#""texture roughness" "flat""#))],
    )
    .unwrap();
    assert!(textured.warnings.is_empty(), "{:?}", textured.warnings);
    let plain = load_text(
        "coat-plain",
        &[("s.pbrt", &scene(r#""float roughness" 0.04"#))],
    )
    .unwrap();
    let (a, b) = (render_film(&textured, 256, 1), render_film(&plain, 256, 2));
    pathlab_testkit::render::assert_same_image("textured against plain coat roughness", &a, &b);
    // The same for a conductor under a smooth coat.
    let base = |roughness: &str| {
        scene("").replace(
            r#""coateddiffuse" "rgb reflectance" [ 0.2 0.4 0.6 ]"#,
            &format!(r#""coatedconductor" {roughness}"#),
        )
    };
    let textured = load_text(
        "coat-base-textured",
        &[("s.pbrt", &base(r#""texture conductor.roughness" "flat""#))],
    )
    .unwrap();
    assert!(textured.warnings.is_empty(), "{:?}", textured.warnings);
    let plain = load_text(
        "coat-base-plain",
        &[("s.pbrt", &base(r#""float conductor.roughness" 0.04"#))],
    )
    .unwrap();
    let (a, b) = (render_film(&textured, 256, 3), render_film(&plain, 256, 4));
    pathlab_testkit::render::assert_same_image("textured against plain base roughness", &a, &b);
    // And for the layer's medium: thickness, albedo and g each a texture of one value.
    let medium = |parameters: &str| {
        scene("")
            .replace(
                r#""rgb reflectance" [ 0.2 0.4 0.6 ]"#,
                &format!(r#""rgb reflectance" [ 0.2 0.4 0.6 ] {parameters}"#),
            )
            .replace(
                "Texture \"flat\"",
                "Texture \"half\" \"spectrum\" \"bilerp\" \"rgb v00\" [ 0.5 0.5 0.5 ] \"rgb v01\" [ 0.5 0.5 0.5 ] \"rgb v10\" [ 0.5 0.5 0.5 ] \"rgb v11\" [ 0.5 0.5 0.5 ]\nTexture \"thick\" \"float\" \"bilerp\" \"float v00\" 1 \"float v01\" 1 \"float v10\" 1 \"float v11\" 1\nTexture \"flat\"",
            )
    };
    let textured = load_text(
        "coat-medium-textured",
        &[(
            "s.pbrt",
            &medium(r#""texture thickness" "thick" "texture albedo" "half" "texture g" "flat""#),
        )],
    )
    .unwrap();
    assert!(textured.warnings.is_empty(), "{:?}", textured.warnings);
    let plain = load_text(
        "coat-medium-plain",
        &[(
            "s.pbrt",
            &medium(r#""float thickness" 1 "rgb albedo" [ 0.5 0.5 0.5 ] "float g" 0.04"#),
        )],
    )
    .unwrap();
    let (a, b) = (render_film(&textured, 256, 5), render_film(&plain, 256, 6));
    pathlab_testkit::render::assert_same_image("textured against plain layer medium", &a, &b);
}

#[test]
fn mix_materials_blend_by_a_number_or_a_texture() {
    use pathlab_render::desc::{MaterialDesc, TextureDesc};
    let materials = r#"MakeNamedMaterial "dark" "string type" "diffuse" "rgb reflectance" [ 0.2 0.2 0.2 ]
MakeNamedMaterial "light" "string type" "diffuse" "rgb reflectance" [ 0.8 0.8 0.8 ]
Texture "quarter" "float" "bilerp" "float v00" 0.25 "float v01" 0.25 "float v10" 0.25 "float v11" 0.25
"#;
    let scene = |mix: &str| {
        FURNACE.to_string()
            + materials
            + &format!(
                "MakeNamedMaterial \"mix\" \"string type\" \"mix\" \"string materials\" [ \"dark\" \"light\" ] {mix}\nNamedMaterial \"mix\"\nShape \"sphere\"\n"
            )
    };
    let weight = |mix: &str, tag: &str| {
        let desc = load_text(tag, &[("s.pbrt", &scene(mix))]).unwrap();
        assert!(desc.warnings.is_empty(), "{:?}", desc.warnings);
        match desc.materials.last() {
            Some(MaterialDesc::Blend { weight, .. }) => (weight.clone(), desc),
            other => panic!("not a blend: {other:?}"),
        }
    };
    // A number: the second material's weight, kept in [0, 1].
    assert_eq!(
        weight(r#""float amount" 0.3"#, "mix-number").0,
        TextureDesc::value(0.3)
    );
    assert_eq!(
        weight(r#""float amount" 1.7"#, "mix-clamped").0,
        TextureDesc::value(1.0)
    );
    // A texture, read at each point: a quarter of the light one renders as their mean.
    let (w, textured) = weight(r#""texture amount" "quarter""#, "mix-texture");
    assert!(w.as_constant().is_none());
    let plain = load_text(
        "mix-plain",
        &[(
            "s.pbrt",
            &(FURNACE.to_string()
                + "Material \"diffuse\" \"rgb reflectance\" [ 0.35 0.35 0.35 ]\nShape \"sphere\"\n"),
        )],
    )
    .unwrap();
    let (a, b) = (render_film(&textured, 64, 1), render_film(&plain, 64, 2));
    pathlab_testkit::render::assert_same_image("mix by texture against its mean", &a, &b);
}
