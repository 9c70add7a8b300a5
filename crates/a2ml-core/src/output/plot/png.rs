//! Pictures as PNG images: the SVG document rendered by resvg, its text set in the DejaVu Sans
//! subset embedded in the library (`assets/`), so that no system font is looked for.

use std::sync::Arc;

use resvg::tiny_skia::{Color, Pixmap, Transform};
use resvg::usvg::{self, fontdb};

use super::{Picture, PlotError};

/// The embedded font (origin and licence in `crates/a2ml-core/assets/README.md`).
const FONT: &[u8] = include_bytes!("../../../assets/DejaVuSans-a2ml.ttf");

/// Its family name, which every generic family of the pictures resolves to.
const FAMILY: &str = "DejaVu Sans";

/// The widest image drawn (px): a 16384 × 10000 image already takes 650 MB to render.
pub const MAX_WIDTH: u32 = 16_384;

/// The size of `picture` drawn `width` pixels wide (its own width when `None`), its height in
/// proportion (at least 1 px).
///
/// # Errors
/// [`PlotError::Size`] for a width of 0 or above [`MAX_WIDTH`].
pub fn scaled_size(picture: &Picture, width: Option<u32>) -> Result<(u32, u32), PlotError> {
    let (own_width, own_height) = picture.size;
    let width = width.unwrap_or(own_width);
    if width == 0 || width > MAX_WIDTH {
        return Err(PlotError::Size { width, max: MAX_WIDTH });
    }
    let height = (f64::from(own_height) * f64::from(width) / f64::from(own_width.max(1))).round();
    Ok((width, (height as u32).max(1)))
}

/// The SVG parser's options: the embedded font for every family.
fn options() -> usvg::Options<'static> {
    let mut fonts = fontdb::Database::new();
    fonts.load_font_data(FONT.to_vec());
    fonts.set_sans_serif_family(FAMILY);
    fonts.set_serif_family(FAMILY);
    fonts.set_monospace_family(FAMILY);
    fonts.set_cursive_family(FAMILY);
    fonts.set_fantasy_family(FAMILY);
    usvg::Options { font_family: FAMILY.to_owned(), fontdb: Arc::new(fonts), ..Default::default() }
}

/// `picture` rendered as a PNG file's bytes, `width` pixels wide (its own when `None`), on
/// white.
///
/// # Errors
/// [`PlotError::Size`] as [`scaled_size`]; [`PlotError::Draw`] when the SVG cannot be read
/// back or the image not encoded.
pub fn png(picture: &Picture, width: Option<u32>) -> Result<Vec<u8>, PlotError> {
    let (w, h) = scaled_size(picture, width)?;
    let failed = |message: String| PlotError::Draw { kind: "png", message };
    let tree = usvg::Tree::from_str(&picture.svg, &options()).map_err(|e| failed(e.to_string()))?;
    let mut pixmap =
        Pixmap::new(w, h).ok_or_else(|| failed(format!("no {w} × {h} image can be made")))?;
    pixmap.fill(Color::WHITE);
    let size = tree.size();
    let scale = Transform::from_scale(w as f32 / size.width(), h as f32 / size.height());
    resvg::render(&tree, scale, &mut pixmap.as_mut());
    pixmap.encode_png().map_err(|e| failed(e.to_string()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_embedded_font_is_the_one_every_family_finds() {
        let options = options();
        let faces: Vec<_> = options.fontdb.faces().collect();
        assert_eq!(faces.len(), 1);
        assert!(faces[0].families.iter().any(|(name, _)| name == FAMILY));
        let query = fontdb::Query { families: &[fontdb::Family::SansSerif], ..Default::default() };
        assert_eq!(options.fontdb.query(&query), Some(faces[0].id));
    }

    #[test]
    fn text_is_drawn_with_it() {
        let picture = |text: &str| Picture {
            svg: format!(
                "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"120\" height=\"40\">\
                 <text x=\"4\" y=\"28\" font-family=\"sans-serif\" font-size=\"24\">{text}</text>\
                 </svg>"
            ),
            size: (120, 40),
            panels: Vec::new(),
        };
        let inked = |bytes: &[u8]| {
            let image = Pixmap::decode_png(bytes).expect("decodes");
            image.pixels().iter().filter(|p| p.red() < 128).count()
        };
        let blank = inked(&png(&picture(""), None).expect("renders"));
        let written = inked(&png(&picture("θsw 42°"), None).expect("renders"));
        assert_eq!(blank, 0);
        assert!(written > 50, "{written} dark pixels");
    }

    #[test]
    fn a_width_out_of_range_is_an_error() {
        let picture = Picture { svg: String::new(), size: (900, 600), panels: Vec::new() };
        assert_eq!(scaled_size(&picture, Some(450)), Ok((450, 300)));
        assert_eq!(scaled_size(&picture, None), Ok((900, 600)));
        for width in [0, MAX_WIDTH + 1] {
            assert_eq!(
                scaled_size(&picture, Some(width)),
                Err(PlotError::Size { width, max: MAX_WIDTH })
            );
        }
    }
}
